// The projection blend modes' pixels (mmrtm/projection.h) for the CPU
// backend, compiled apart from the path tracer (why: ProjectPixel).
#pragma once

#include "mmrtm/counters.h"
#include "mmrtm/scene_view.h"

namespace mmrtm {

PixelSample ProjectPixelOnCpu(const SceneView& s, int x, int y, TraceCounters& ctr);

}  // namespace mmrtm
