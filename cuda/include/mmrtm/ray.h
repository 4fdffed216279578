// Rays and the ray-box test (pbrt-v4's Bounds3::IntersectP).
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

struct Ray {
  Vec3 o, d;
  MMRTM_CPU_GPU Vec3 operator()(float t) const { return o + d * t; }
};

// Slab test against the box [lo, hi]; on a hit returns the parametric
// interval clipped to [0, tMax]. The gamma(3) factor of pbrt keeps the far
// distance conservative under rounding.
MMRTM_CPU_GPU inline bool IntersectBox(Vec3 o, Vec3 d, Vec3 lo, Vec3 hi, float tMax, float* t0Out, float* t1Out) {
  float t0 = 0.f, t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    float inv = 1.f / d[a];
    float tNear = (lo[a] - o[a]) * inv, tFar = (hi[a] - o[a]) * inv;
    if (tNear > tFar) {
      float tmp = tNear;
      tNear = tFar;
      tFar = tmp;
    }
    tFar *= 1.f + 2.f * 3.f * 0x1p-24f;
    // NaN-safe: a NaN (o on a slab plane with d parallel to it) keeps t0/t1.
    t0 = tNear > t0 ? tNear : t0;
    t1 = tFar < t1 ? tFar : t1;
    if (t0 > t1) return false;
  }
  *t0Out = t0;
  *t1Out = t1;
  return true;
}

}  // namespace mmrtm
