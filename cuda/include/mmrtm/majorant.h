// Majorants as an iterator (pbrt-v4's RayMajorantIterator shape): the tracker
// asks for segments {tMin, tMax, sigma_maj} along a ray, one after another,
// and never knows who produced them. Here: the global majorant, one segment
// over the whole volume (the baseline "none"). The grids of the accelerator
// add kinds to MajorantSource and MajorantIterator without touching the
// trackers.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/ray.h"

namespace mmrtm {

struct RayMajorantSegment {
  float tMin = 0.f, tMax = 0.f, sigma_maj = 0.f;
};

enum class MajorantKind : uint8_t { Global };

class MajorantIterator {
 public:
  MajorantIterator() = default;
  MMRTM_CPU_GPU static MajorantIterator Single(float tMin, float tMax, float sigma_maj) {
    MajorantIterator it;
    it.segment_ = {tMin, tMax, sigma_maj};
    it.pending_ = tMin < tMax;
    return it;
  }

  MMRTM_CPU_GPU bool Next(RayMajorantSegment* seg) {
    if (!pending_) return false;
    *seg = segment_;
    pending_ = false;
    return true;
  }

 private:
  RayMajorantSegment segment_;
  bool pending_ = false;
};

struct MajorantSource {
  MajorantKind kind = MajorantKind::Global;
  float globalMajorant = 0.f;  // bounds sigma_t everywhere in the volume

  // Segments over [tMin, tMax] of a ray given in the volume's index space
  // (its parameter t is the world distance). `scale` multiplies every
  // majorant (the shadow-ray extinction scale).
  MMRTM_CPU_GPU MajorantIterator Begin(const Ray& indexRay, float tMin, float tMax, float scale) const {
    (void)indexRay;
    return MajorantIterator::Single(tMin, tMax, globalMajorant * scale);
  }
};

}  // namespace mmrtm
