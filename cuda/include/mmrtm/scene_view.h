// Everything the per-pixel integrator reads, as views: proxies and TFs
// (through the classifier), majorants, lights, camera and settings. Built by
// the host scene (cuda/host/scene.h); copied by value to a backend.
#pragma once

#include "mmrtm/camera.h"
#include "mmrtm/classifier.h"
#include "mmrtm/lights.h"
#include "mmrtm/majorant.h"

namespace mmrtm {

enum class Estimator : uint8_t {
  DeltaTracking,  // unbiased: delta tracking + ratio tracking (the default)
  RayMarching     // biased baseline: ExposureRenderer-style ray marching
};

// Paper section 3.3: shadow rays see sigma_t times this. An artistic bias;
// 1 is the unbiased estimator (DESIGN.md rule 5).
constexpr float kDefaultShadowExtinctionScale = 0.8f;

// Next-event estimation with several lights.
enum class LightSampling {
  One,       // one light chosen uniformly, one shadow ray
  All,       // a shadow ray to every light
  Resampled  // one light chosen by its unshadowed contribution, one shadow ray
};

// Where the first dimensions of a path come from (mmrtm/sobol.h).
enum class PixelSampler : uint8_t {
  Independent,  // every number from the sample's PCG32 stream
  Sobol         // Owen-scrambled Sobol' pairs for the pixel, the lens and the
                // first two vertices (the default); the rest from the stream
};

// VTK's projection blend modes (mmrtm/projection.h); None traces paths.
enum class IntensityProjection : uint8_t { None, Maximum, Minimum, Average, Additive };

struct ProjectionSettings {
  IntensityProjection mode = IntensityProjection::None;
  float step = 1.f;                                 // world units between the samples along a ray
  float opacityUnitDistance = 1.f;                  // the scalar opacity's unit distance (the translation's)
  float valueRange[2] = {0.f, 1.f};                 // proxy 0's values mapped to [0, 1] (Average, Additive)
  float averageRange[2] = {-kInfinity, kInfinity};  // the values Average counts
};

struct IntegratorSettings {
  Estimator estimator = Estimator::DeltaTracking;
  int maxBounces = 32;           // real scattering events per path
  int russianRouletteDepth = 3;  // bounces before Russian roulette starts
  float shadowExtinctionScale = kDefaultShadowExtinctionScale;
  float rayMarchStep = 0.5f;      // ray marching step, world units
  bool backgroundVisible = true;  // camera rays that escape see the environment
  LightSampling lightSampling = LightSampling::Resampled;
  PixelSampler sampler = PixelSampler::Sobol;
  uint64_t seed = 0;
  ProjectionSettings projection;
  // Whether Li reports the denoiser's guides (PixelSample::albedo and
  // normal). They use no random numbers: the radiance is the same either way.
  bool firstHitGuides = false;
};

// A half-space that is kept: points with Dot(normal, p) + offset >= 0 (VTK's
// clipping planes, cropping). World space.
struct ClipPlane {
  Vec3 normal;
  float offset = 0.f;
};
constexpr int kMaxClipPlanes = 12;

struct SceneView {
  Classifier classifier;
  MajorantSource majorants;
  int domain[3] = {1, 1, 1};  // voxel counts of proxy 0: the tracked box is [0, n-1]
  const Light* lights = nullptr;
  int lightCount = 0;
  int environmentLight = -1;  // index of the environment in lights, or -1
  EnvironmentView environment;
  CameraView camera;
  // Optional, camera.width * camera.height floats, row 0 at the top: how
  // far each pixel's camera ray may go before opaque geometry that the host
  // application drew (kInfinity where there is none). Null: no limit.
  const float* cameraRayMaxDistance = nullptr;
  IntegratorSettings settings;
  // The volume is seen only inside every clip plane's half-space (a convex
  // region, so each ray's part inside is one interval).
  ClipPlane clipPlanes[kMaxClipPlanes];
  int clipPlaneCount = 0;

  // The ray in proxy 0's index space, and its parametric interval inside the
  // volume and the clip planes. t is the world distance along the (unit)
  // world direction. Every free path and transmittance goes through here.
  MMRTM_CPU_GPU bool DomainInterval(const Ray& world, float tMax, Ray* indexRay, float* t0, float* t1) const {
    const Affine3& w2i = classifier.proxies[0].worldToIndex;
    indexRay->o = w2i.ApplyPoint(world.o);
    indexRay->d = w2i.ApplyVector(world.d);
    if (!IntersectBox(indexRay->o, indexRay->d, Vec3{0.f, 0.f, 0.f},
                      Vec3{(float)(domain[0] - 1), (float)(domain[1] - 1), (float)(domain[2] - 1)}, tMax, t0, t1))
      return false;
    for (int i = 0; i < clipPlaneCount; ++i) {
      const float along = Dot(clipPlanes[i].normal, world.d);
      const float at0 = Dot(clipPlanes[i].normal, world.o) + clipPlanes[i].offset;  // signed distance at t = 0
      if (along == 0.f) {
        if (at0 < 0.f) return false;
        continue;
      }
      const float t = -at0 / along;
      if (along > 0.f)
        *t0 = Max(*t0, t);  // entering the kept side
      else
        *t1 = Min(*t1, t);  // leaving it
    }
    return *t0 < *t1;
  }
};

// One sample of a pixel: the radiance, and 1 when the camera ray collided
// with the volume.
struct PixelSample {
  RGB L;
  float alpha = 0.f;
  // The denoiser's guides (IntegratorSettings::firstHitGuides), where the
  // camera ray first collides: the albedo (a glowing material's bounded
  // emission, which is its colour) and the unit gradient normal facing the
  // camera; zero where the ray escapes or the point has no gradient.
  RGB albedo;
  Vec3 normal;
};

}  // namespace mmrtm
