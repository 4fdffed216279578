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

struct IntegratorSettings {
  Estimator estimator = Estimator::DeltaTracking;
  int maxBounces = 32;         // real scattering events per path
  int russianRouletteDepth = 3;  // bounces before Russian roulette starts
  float shadowExtinctionScale = kDefaultShadowExtinctionScale;
  float rayMarchStep = 0.5f;   // ray marching step, world units
  bool backgroundVisible = true;  // camera rays that escape see the environment
  uint64_t seed = 0;
};

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

  // The ray in proxy 0's index space, and its parametric interval inside the
  // volume. t is the world distance along the (unit) world direction.
  MMRTM_CPU_GPU bool DomainInterval(const Ray& world, float tMax, Ray* indexRay, float* t0, float* t1) const {
    const Affine3& w2i = classifier.proxies[0].worldToIndex;
    indexRay->o = w2i.ApplyPoint(world.o);
    indexRay->d = w2i.ApplyVector(world.d);
    return IntersectBox(indexRay->o, indexRay->d, Vec3{0.f, 0.f, 0.f},
                        Vec3{(float)(domain[0] - 1), (float)(domain[1] - 1), (float)(domain[2] - 1)}, tMax, t0, t1);
  }
};

}  // namespace mmrtm
