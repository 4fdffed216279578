// Henyey-Greenstein phase function (pbrt-v4 section 11.3).
//
// Directions follow pbrt: wo points back toward the previous vertex, wi is
// the new direction; both point away from the scattering point. g > 0 is
// forward scattering (wi close to -wo).
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/planted_defect.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

struct PhaseSample {
  Vec3 wi;
  float p = 0.f;    // phase function value
  float pdf = 0.f;  // equals p: HG is sampled exactly
};

MMRTM_CPU_GPU inline float HenyeyGreenstein(float cosTheta, float g) {
  // cosTheta between the travel directions -wo and wi.
  if (Planted(Defect::PhaseSign)) g = -g;
  float denom = 1.f + g * g - 2.f * g * cosTheta;
  return kInv4Pi * (1.f - g * g) / (denom * SafeSqrt(denom));
}

struct HGPhaseFunction {
  float g = 0.f;

  MMRTM_CPU_GPU float p(Vec3 wo, Vec3 wi) const { return HenyeyGreenstein(Dot(-wo, wi), g); }
  MMRTM_CPU_GPU float Pdf(Vec3 wo, Vec3 wi) const { return p(wo, wi); }

  MMRTM_CPU_GPU PhaseSample Sample(Vec3 wo, float u0, float u1) const {
    float cosTheta;
    if (fabsf(g) < 1e-3f) {
      cosTheta = 1.f - 2.f * u0;
    } else {
      const float gs = Planted(Defect::PhaseSign) ? -g : g;
      float s = (1.f - gs * gs) / (1.f - gs + 2.f * gs * u0);
      cosTheta = Clamp((1.f + gs * gs - s * s) / (2.f * gs), -1.f, 1.f);
    }
    float sinTheta = SafeSqrt(1.f - cosTheta * cosTheta);
    float phi = 2.f * kPi * u1;
    Frame frame = Frame::FromZ(-wo);
    Vec3 wi = frame.FromLocal({sinTheta * cosf(phi), sinTheta * sinf(phi), cosTheta});
    float value = HenyeyGreenstein(cosTheta, g);
    return {wi, value, value};
  }
};

}  // namespace mmrtm
