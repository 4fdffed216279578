// Lights: directional, point, and an equirectangular environment map with
// importance sampling over its texels (as pbrt-v4's ImageInfiniteLight, here
// on a latitude-longitude parameterisation). World up is +z (superior in LPS), which is the
// environment's zenith.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/planted_defect.h"
#include "mmrtm/sampling.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

enum class LightType : uint8_t { Directional, Point, Environment };

struct EnvironmentView {
  const RGB* texels = nullptr;  // width*height, row 0 at the zenith
  int width = 0, height = 0;
  Distribution2DView distribution;  // over (u, v), proportional to luminance * sin(theta)

  // (u, v) in [0,1)^2 for direction w: u from azimuth, v from polar angle.
  MMRTM_CPU_GPU static void DirectionToUV(Vec3 w, float* u, float* v) {
    float phi = atan2f(w.y, w.x);
    if (phi < 0.f) phi += 2.f * kPi;
    *u = Clamp(phi * kInv2Pi, 0.f, kOneMinusEpsilon);
    *v = Clamp(acosf(Clamp(w.z, -1.f, 1.f)) * kInvPi, 0.f, kOneMinusEpsilon);
  }
  // The direction of (u, v); `sinTheta`, when given, the sine of its polar
  // angle (the Jacobian's factor).
  MMRTM_CPU_GPU static Vec3 UVToDirection(float u, float v, float* sinTheta = nullptr) {
    float phi = u * 2.f * kPi, theta = v * kPi;
    float s = sinf(theta);
    if (sinTheta) *sinTheta = s;
    return {s * cosf(phi), s * sinf(phi), cosf(theta)};
  }
  // Solid-angle pdf from the (u, v) pdf, at a polar angle of sine sinTheta.
  MMRTM_CPU_GPU static float SolidAnglePdf(float pdfUV, float sinTheta) {
    if (Planted(Defect::EnvironmentPdf)) pdfUV *= 1.05f;
    return sinTheta > 0.f ? pdfUV / (2.f * kPi * kPi * sinTheta) : 0.f;
  }

  MMRTM_CPU_GPU RGB Texel(float u, float v) const {
    int x = ClampInt((int)(u * width), 0, width - 1), y = ClampInt((int)(v * height), 0, height - 1);
    return texels[x + width * y];
  }
  MMRTM_CPU_GPU RGB Le(Vec3 w) const {
    float u, v;
    DirectionToUV(w, &u, &v);
    return Texel(u, v);
  }
  // Solid-angle pdf of sampling the direction of (u, v).
  MMRTM_CPU_GPU float PdfAtUV(float u, float v) const { return SolidAnglePdf(distribution.Pdf(u, v), sinf(v * kPi)); }
  // Solid-angle pdf of sampling direction w.
  MMRTM_CPU_GPU float Pdf(Vec3 w) const {
    float u, v;
    DirectionToUV(w, &u, &v);
    return PdfAtUV(u, v);
  }
  // Le(w) and Pdf(w) from one conversion of w to (u, v).
  MMRTM_CPU_GPU RGB LeAndPdf(Vec3 w, float* pdf) const {
    float u, v;
    DirectionToUV(w, &u, &v);
    *pdf = PdfAtUV(u, v);
    return Texel(u, v);
  }
};

struct Light {
  LightType type = LightType::Directional;
  uint8_t padding[3] = {};  // explicit: equal lights have equal bytes (scene_uploads.h)
  Vec3 vector;              // directional: unit direction toward the light; point: position
  RGB L;                    // directional: irradiance at normal incidence; point: intensity
  // Directional: the plane dot(x, vector) = start that the light leaves
  // from (a headlight leaves from the camera: what is behind the camera
  // neither shadows nor receives it); kInfinity: from infinitely far.
  float start = kInfinity;
};

struct LightSample {
  Vec3 wi;  // toward the light
  float distance = kInfinity;
  RGB L;            // incident radiance (delta lights: irradiance)
  float pdf = 0.f;  // solid-angle pdf; 1 for delta lights
  bool isDelta = true;
};

MMRTM_CPU_GPU inline LightSample SampleLight(const Light& light, const EnvironmentView& env, Vec3 p, float u0,
                                             float u1) {
  LightSample s;
  switch (light.type) {
    case LightType::Directional:
      s.wi = light.vector;
      s.L = light.L;
      s.distance = light.start - Dot(p, light.vector);  // kInfinity when it has no start
      s.pdf = s.distance > 0.f ? 1.f : 0.f;             // behind its start: no light
      break;
    case LightType::Point: {
      Vec3 d = light.vector - p;
      float d2 = LengthSquared(d);
      s.distance = sqrtf(d2);
      s.wi = d / s.distance;
      s.L = light.L / d2;
      s.pdf = 1.f;
      break;
    }
    case LightType::Environment: {
      float u, v, pdfUV, sinTheta;
      int col, row;
      env.distribution.Sample(u0, u1, &u, &v, &pdfUV, &col, &row);
      s.wi = EnvironmentView::UVToDirection(u, v, &sinTheta);
      // The radiance and pdf of the texel that was sampled (the distribution
      // is over the texels), not of wi converted back to (u, v): that round
      // trip cost an atan2f, an acosf and a sinf twice per light sample, and
      // lands in the same texel but where float rounding crosses a texel
      // edge, a set of directions of measure zero.
      s.pdf = EnvironmentView::SolidAnglePdf(pdfUV, sinTheta);
      if (s.pdf <= 0.f) return s;                                                           // pdf 0: no sample
      MMRTM_DCHECK(env.distribution.nu == env.width && env.distribution.nv == env.height);  // a bucket per texel
      s.L = env.texels[col + env.width * row];
      s.isDelta = false;
      break;
    }
  }
  return s;
}

}  // namespace mmrtm
