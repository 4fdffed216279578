// Auxiliary images for the denoised preview (Documentation/denoising.md):
// where a camera ray first collides, the material's albedo and the surface
// normal (the gradient of the gradient proxy). A denoiser keeps the edges
// these images have and smooths the noise they do not.
//
// Not part of the radiance estimate: the feature samples have a random
// stream of their own (a seed of their own), so the unbiased image is the
// same whether or not a preview is made, and they trace only to the first
// collision (no lights, no shadow rays).
#pragma once

#include "mmrtm/tracking.h"

namespace mmrtm {

struct FirstHitFeatures {
  RGB albedo;   // the collision's albedo; what the background shows where the ray escapes
  Vec3 normal;  // unit gradient normal facing the camera; zero where there is none
};

// Feature samples use seed ^ this, so their streams are never the radiance's.
constexpr uint64_t kFeatureSeedSalt = 0x6a09e667f3bcc909ULL;

MMRTM_CPU_GPU inline FirstHitFeatures TraceFirstHitFeatures(const SceneView& s, int x, int y, uint32_t sampleIndex,
                                                            TraceCounters& ctr) {
  const int64_t pixel = x + (int64_t)s.camera.width * y;
  PCG32 rng = PixelSampleRNG(s.settings.seed ^ kFeatureSeedSalt, (uint64_t)pixel, sampleIndex);
  const float fx = rng.Uniform(), fy = rng.Uniform(), l0 = rng.Uniform(), l1 = rng.Uniform();
  const Ray ray = s.camera.GenerateRay((float)x + fx, (float)y + fy, l0, l1);
  const float tMax = s.cameraRayMaxDistance ? s.cameraRayMaxDistance[pixel] : kInfinity;
  FirstHitFeatures f;
  const FreePathResult fp = SampleFreePath(s, ray, tMax, rng, ctr);
  if (!fp.collided) {
    // The background as albedo (OIDN's advice for what a ray sees directly),
    // clamped to the albedo's range; opaque geometry in front: nothing.
    if (tMax == kInfinity && s.settings.backgroundVisible && s.environmentLight >= 0) {
      const RGB Le = s.environment.Le(ray.d);
      f.albedo = RGB(Clamp(Le.r, 0.f, 1.f), Clamp(Le.g, 0.f, 1.f), Clamp(Le.b, 0.f, 1.f));
    }
    return f;
  }
  const Vec3 p = ray(fp.t);
  f.albedo = s.classifier.Coefficients(fp.c).albedo;
  const Vec3 g = s.classifier.Gradient(p);
  const float len = Length(g);
  if (len > 0.f && isfinite(len)) f.normal = Dot(g, ray.d) > 0.f ? g / -len : g / len;
  return f;
}

}  // namespace mmrtm
