#include "cpu_projection.h"

#include "mmrtm/projection.h"

namespace mmrtm {

PixelSample ProjectPixelOnCpu(const SceneView& s, int x, int y, TraceCounters& ctr) {
  return ProjectPixel(s, x, y, ctr);
}

}  // namespace mmrtm
