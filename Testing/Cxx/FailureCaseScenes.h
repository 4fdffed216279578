// Scenes where volume rendering methods are known to fail, with the quantity
// each one gets wrong and its exact value. Shared by the failure-case tests
// (TestFailureCases.cpp, which assert) and the benchmark that charts them
// (Testing/Benchmarks/mmrtm-bench-failure-cases.cpp, which prints curves).
//
// Every case measures a transmittance along one ray, whose exact value is
// known in closed form, so a failure shows as a bias, not as a vague
// difference between images:
//   - NarrowPeak: a TF peak narrower than a voxel's value step. Ray marching
//     steps over it; the paper's voxel-value refit gives it no majorant.
//   - SparseBlock: one dense block in a large empty volume. The global
//     majorant makes every ray take ~sigma_max x length tentative steps.
//   - SliceSheet: density on one voxel slice, rays grazing along it, exactly
//     on a face between majorant-grid nodes.
//   - SaturatedBlock: a TF step at the data maximum (a saturated block of
//     voxels), the top edge of the value bins.
//   - AllZeroTF, AllOneTF: the other degenerate TFs.
//   - DensePathCost: whole paths in very dense media (counts, not a bias).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "TestSceneHelpers.h"
#include "mmrtm/integrator.h"
#include "mmrtm/rng.h"
#include "mmrtm/tracking.h"

namespace mmrtm::failure {

enum class Method { DeltaTracking, RatioTracking, RayMarching };

struct Estimate {
  double mean = 0, standardError = 0;
  double lookupsPerRay = 0;
  uint64_t violations = 0;
};

// `trials` independent transmittance estimates along `ray`, averaged.
inline Estimate Transmittance(const SceneView& s, const Ray& ray, Method method, int trials, uint64_t seed) {
  PCG32 rng(seed, 11);
  TraceCounters ctr;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < trials; ++i) {
    double T = 0;
    switch (method) {
      case Method::DeltaTracking:
        T = DeltaTrack(s, ray, kInfinity, rng, ctr).collided ? 0.0 : 1.0;
        break;
      case Method::RatioTracking:
        T = RatioTrack(s, ray, kInfinity, 1.f, rng, ctr);
        break;
      case Method::RayMarching:
        T = RayMarchTransmittance(s, ray, kInfinity, 1.f, rng, ctr);
        break;
    }
    sum += T;
    sum2 += T * T;
  }
  Estimate e;
  e.mean = sum / trials;
  // At least float rounding: residual ratio tracking in a constant medium
  // has no variance, and its estimate is exp() in float.
  e.standardError = std::max(std::sqrt(std::max(sum2 / trials - e.mean * e.mean, 0.0) / trials), 1e-6 * e.mean);
  e.lookupsPerRay = (double)ctr.densityLookups / trials;
  e.violations = ctr.majorantViolations;
  return e;
}

// A material of density `density` times a TF over proxy 0.
inline Scene SceneWithTF(HostVolume volume, TransferFunctionDesc tf, float density, MajorantKind kind,
                         SummaryMode summary = SummaryMode::CellRanges) {
  Scene s = test::MakeMediumScene(std::move(volume), density, RGB(1.f));
  tf.where = "failure case";
  s.tfs[0] = std::move(tf);
  s.render.accelerator.kind = kind;
  s.render.accelerator.grid.summary = summary;
  return s;
}

inline TransferFunctionDesc CCTF(std::vector<float> keys, std::vector<float> values) {
  TransferFunctionDesc tf;
  tf.type = TFType::CCTF;
  tf.keys = std::move(keys);
  tf.values = std::move(values);
  return tf;
}

// A case: the scene, one ray through it and the exact transmittance.
struct Case {
  Scene scene;
  Ray ray;
  double exact;
};

// `trials` estimates of the case's transmittance (seed 1).
inline Estimate Measure(Case& c, Method method, int trials = 100000) {
  SceneView s = c.scene.Build();
  return Transmittance(s, c.ray, method, trials, 1);
}

// Values rise by 1 per voxel along x (0 .. 20, 1 mm voxels); a triangular TF
// peak of half-width `halfWidth` at 10.5 (between two voxel values), density
// `density` at its top. Along x the value is x, so the optical depth is the
// peak's area times the density: density * halfWidth.
inline Case NarrowPeak(float halfWidth, float density, MajorantKind kind, SummaryMode summary, float step = 0.5f) {
  Case c{SceneWithTF(test::MakeVolume(21, 5, 5, [](int i, int, int) { return (float)i; }),
                     CCTF({10.5f - halfWidth, 10.5f, 10.5f + halfWidth}, {0.f, 1.f, 0.f}), density, kind, summary),
         Ray{{-1.f, 2.f, 2.f}, {1.f, 0.f, 0.f}}, std::exp(-(double)density * halfWidth)};
  c.scene.render.integrator.rayMarchStep = step;
  return c;
}

// An n^3 volume (1 mm voxels), zero but for a 2^3 block of ones at its centre,
// density `density`. The ray runs along x through the middle of the block:
// the interpolated value there rises over 1 mm, stays 1 for 1 mm and falls
// over 1 mm, an optical depth of 2 * density.
inline Case SparseBlock(int n, float density, MajorantKind kind) {
  const int c0 = n / 2 - 1;
  auto inBlock = [c0](int i) { return i == c0 || i == c0 + 1; };
  Case c{
      SceneWithTF(test::MakeVolume(
                      n, n, n, [&](int i, int j, int k) { return inBlock(i) && inBlock(j) && inBlock(k) ? 1.f : 0.f; }),
                  CCTF({0.f, 1.f}, {0.f, 1.f}), density, kind),
      Ray{{-1.f, c0 + 0.5f, c0 + 0.5f}, {1.f, 0.f, 0.f}}, std::exp(-2.0 * density)};
  return c;
}

// A 33^3 volume (1 mm voxels) whose slice k = 16 holds 1 and the rest 0:
// a sheet one voxel thick. z = 16 is also a face between majorant-grid nodes
// at every level coarser than a cell. A ray along x at height z sees
// value max(0, 1 - |z - 16|) over the 32 mm of the box, for optical depth
// density * 32 * that value; `tilt` (radians) tips it across the sheet,
// leaving it in the sheet's plane at the box's centre.
inline Case SliceSheet(float z, float density, MajorantKind kind, float tilt = 0.f) {
  Case c{SceneWithTF(test::MakeVolume(33, 33, 33, [](int, int, int k) { return k == 16 ? 1.f : 0.f; }),
                     CCTF({0.f, 1.f}, {0.f, 1.f}), density, kind),
         Ray{}, 0.0};
  const Vec3 d = Normalize(Vec3{std::cos(tilt), 0.f, std::sin(tilt)});
  c.ray = Ray{Vec3{16.f, 16.25f, z} - d * 20.f, d};
  if (tilt == 0.f) {
    c.exact = std::exp(-(double)density * 32.0 * std::max(0.0, 1.0 - std::abs(z - 16.0)));
  } else {
    // Across the sheet the value is a tent of area 1 in z (clipped by the
    // box in x for small tilts): integrate the tent along the ray numerically.
    double depth = 0;
    const int steps = 200000;
    for (int i = 0; i < steps; ++i) {
      const double t = (i + 0.5) / steps * 40.0;
      const double x = c.ray.o.x + t * d.x, zz = c.ray.o.z + t * d.z;
      if (x < 0 || x > 32 || zz < 0 || zz > 32) continue;
      depth += std::max(0.0, 1.0 - std::abs(zz - 16.0)) * (40.0 / steps);
    }
    c.exact = std::exp(-(double)density * depth);
  }
  return c;
}

// A uint8-like volume (values 0 .. 255, stored as float) of noise below 250
// with a 4^3 block of saturated voxels (255); a TF that is 0 up to 254.999
// and 1 at 255 (a step at the data maximum). The ray runs along x through
// the block's inner voxel centres, where the interpolated value is 255 for
// the 3 mm between the block's first and last voxel centre (and falls below
// 254.999 within 1e-4 mm outside them).
inline Case SaturatedBlock(float density, MajorantKind kind) {
  auto inBlock = [](int i) { return i >= 14 && i <= 17; };
  Case c{SceneWithTF(test::MakeVolume(32, 32, 32,
                                      [&](int i, int j, int k) {
                                        if (inBlock(i) && inBlock(j) && inBlock(k)) return 255.f;
                                        return (float)((i * 7919 + j * 104729 + k * 1299709) % 250);
                                      }),
                     CCTF({254.999f, 255.f}, {0.f, 1.f}), density, kind),
         Ray{{-1.f, 15.f, 16.f}, {1.f, 0.f, 0.f}}, std::exp(-3.0 * density)};
  return c;
}

// Degenerate TFs over a 16^3 (all zero) or 17^3 (all one, over noisy data)
// volume, 1 mm voxels, ray along x: T = 1, and Beer-Lambert over 16 mm at
// extinction 0.1.
inline Case AllZeroTF(MajorantKind kind) {
  return {SceneWithTF(test::MakeConstantVolume(16, 100.f), CCTF({0.f, 1000.f}, {0.f, 0.f}), 1.f, kind),
          Ray{{-2.f, 7.3f, 7.6f}, {1.f, 0.f, 0.f}}, 1.0};
}

inline Case AllOneTF(MajorantKind kind) {
  return {SceneWithTF(
              test::MakeVolume(17, 17, 17, [](int i, int j, int k) { return float((i * 31 + j * 17 + k * 7) % 100); }),
              CCTF({0.f, 99.f}, {1.f, 1.f}), 0.1f, kind),
          Ray{{-2.f, 8.3f, 8.6f}, {1.f, 0.f, 0.f}}, std::exp(-0.1 * 16.0)};
}

// --- Very dense media: the cost of whole paths ---

struct PathCost {
  double lookupsPerPath, realPerPath;
  uint64_t maxRealPerPath;
};

// Paths from a camera into a ball of density `density` (smooth edge, 1 mm
// voxels), rendered one path at a time to see each path's own count.
inline PathCost DensePathCost(float density, RGB albedo, int maxBounces, int leafLevel = -1) {
  Scene scene = test::MakeMediumScene(
      test::MakeVolume(33, 33, 33,
                       [](int i, int j, int k) {
                         float r = std::sqrt(float((i - 16) * (i - 16) + (j - 16) * (j - 16) + (k - 16) * (k - 16)));
                         return std::clamp(12.f - r, 0.f, 1.f);
                       }),
      density, albedo);
  scene.environment = EnvironmentMap::Constant(RGB(1.f));
  scene.render.integrator.maxBounces = maxBounces;
  scene.render.accelerator.grid.leafLevel = leafLevel;
  scene.render.width = scene.render.height = 16;
  SceneView s = scene.Build();
  PathCost cost{0, 0, 0};
  TraceCounters total;
  int paths = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (uint32_t i = 0; i < 8; ++i) {
        TraceCounters ctr;
        RenderPixelSample(s, x, y, i, ctr);
        cost.maxRealPerPath = std::max<uint64_t>(cost.maxRealPerPath, ctr.realCollisions);
        total.densityLookups += ctr.densityLookups;
        total.realCollisions += ctr.realCollisions;
        ++paths;
      }
  cost.lookupsPerPath = (double)total.densityLookups / paths;
  cost.realPerPath = (double)total.realCollisions / paths;
  return cost;
}

}  // namespace mmrtm::failure
