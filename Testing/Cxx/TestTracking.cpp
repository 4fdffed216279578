// Transmittance of slabs against Beer-Lambert, by delta tracking (the
// probability of crossing without a real collision) and by residual ratio
// tracking (the mean of its estimates). Tolerances are 4 standard errors of
// each estimator, computed from the estimator's own variance (and at least
// float rounding, for an estimator without variance): test::ExpectUnbiased
// (ExpectAgreement.h) states the false-failure probability and prints each
// check's power.
#include <gtest/gtest.h>

#include <cmath>

#include "ExpectAgreement.h"
#include "TestSceneHelpers.h"
#include "mmrtm/tracking.h"

namespace mmrtm {
namespace {

constexpr int kTrials = 200000;

struct Estimate {
  double mean, standardError;
};

Estimate DeltaTransmittance(const SceneView& s, Ray ray, float tMax) {
  PCG32 rng(1, 2);
  TraceCounters ctr;
  int escaped = 0;
  for (int i = 0; i < kTrials; ++i) escaped += DeltaTrack(s, ray, tMax, rng, ctr).collided ? 0 : 1;
  double p = (double)escaped / kTrials;
  EXPECT_EQ(ctr.majorantViolations, 0u);
  return {p, std::sqrt(std::max(p * (1 - p), 1e-12) / kTrials)};
}

Estimate RatioTransmittance(const SceneView& s, Ray ray, float tMax, float scale, TraceCounters* counters = nullptr) {
  PCG32 rng(3, 4);
  TraceCounters local;
  TraceCounters& ctr = counters ? *counters : local;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < kTrials; ++i) {
    double T = RatioTrack(s, ray, tMax, scale, rng, ctr);
    sum += T;
    sum2 += T * T;
  }
  double mean = sum / kTrials;
  EXPECT_EQ(ctr.majorantViolations, 0u);
  return {mean, std::max(std::sqrt(std::max(sum2 / kTrials - mean * mean, 0.0) / kTrials), 1e-6 * mean)};
}

TEST(Tracking, HomogeneousSlabFollowsBeerLambert) {
  // 33 voxels of spacing 0.5: a box 16 mm wide, sigma_t = 0.15 / mm.
  Scene scene = test::MakeMediumScene(test::MakeConstantVolume(33, 1.f, 0.5f), 0.15f, RGB(1.f));
  SceneView s = scene.Build();
  const Ray ray{{-5.f, 8.f, 8.f}, {1.f, 0.f, 0.f}};
  const double expected = std::exp(-0.15 * 16.0);
  Estimate d = DeltaTransmittance(s, ray, kInfinity);
  test::ExpectUnbiased(d.mean, d.standardError, expected, "slab, delta tracking");
  Estimate r = RatioTransmittance(s, ray, kInfinity, 1.f);
  test::ExpectUnbiased(r.mean, r.standardError, expected, "slab, ratio tracking");
  // The shadow extinction scale multiplies the optical depth.
  Estimate scaled = RatioTransmittance(s, ray, kInfinity, 0.8f);
  test::ExpectUnbiased(scaled.mean, scaled.standardError, std::exp(-0.8 * 0.15 * 16.0), "slab, scale 0.8");
  // A shadow ray ending inside the slab sees only part of it.
  Estimate partial = RatioTransmittance(s, ray, 5.f + 4.f, 1.f);
  test::ExpectUnbiased(partial.mean, partial.standardError, std::exp(-0.15 * 4.0), "slab, a shadow ray ending inside");
}

TEST(Tracking, LinearRampFollowsBeerLambert) {
  // sigma_t grows linearly along x from 0 to 0.4 over 20 mm, trilinearly
  // interpolated between voxel centres: optical depth 0.5 * 0.4 * 20 = 4.
  const int n = 21;
  Scene scene =
      test::MakeMediumScene(test::MakeVolume(n, 5, 5, [](int i, int, int) { return i / 20.f; }), 0.4f, RGB(1.f));
  SceneView s = scene.Build();
  const Ray ray{{-1.f, 2.f, 2.f}, {1.f, 0.f, 0.f}};
  const double expected = std::exp(-4.0);
  Estimate d = DeltaTransmittance(s, ray, kInfinity);
  test::ExpectUnbiased(d.mean, d.standardError, expected, "ramp, delta tracking");
  Estimate r = RatioTransmittance(s, ray, kInfinity, 1.f);
  test::ExpectUnbiased(r.mean, r.standardError, expected, "ramp, ratio tracking");
}

TEST(Tracking, ResidualRatioTrackingIsExactWhereTheExtinctionIsConstant) {
  // The grid's minorant equals its majorant in a constant medium: the
  // control part exp(-sigma_min * length) is all of the transmittance, every
  // estimate is exact, and no lookup is needed.
  // (A transmittance above the roulette's threshold: 0.2. A TF constant
  // over all values: the summaries' first bin also holds every value below
  // the volume's, where an identity TF would go down to 0.)
  Scene scene = test::MakeMediumScene(test::MakeConstantVolume(33, 1.f, 0.5f), 0.1f, RGB(1.f));
  for (float& v : scene.tfs[0].values) v = 1.f;
  SceneView s = scene.Build();
  const Ray ray{{-5.f, 8.f, 8.f}, {1.f, 0.f, 0.f}};
  PCG32 rng(7, 8);
  TraceCounters ctr;
  for (int i = 0; i < 1000; ++i) ASSERT_NEAR(RatioTrack(s, ray, kInfinity, 1.f, rng, ctr), std::exp(-0.1 * 16.0), 1e-6);
  EXPECT_EQ(ctr.densityLookups, 0u);
}

TEST(Tracking, ResidualRatioTrackingHasLessVarianceThanRatioTracking) {
  // The ramp of LinearRampFollowsBeerLambert: plain ratio tracking (the
  // same view without minorants) and residual ratio tracking both agree
  // with Beer-Lambert; the residual one with less variance and fewer lookups.
  const int n = 21;
  Scene scene =
      test::MakeMediumScene(test::MakeVolume(n, 5, 5, [](int i, int, int) { return i / 20.f; }), 0.4f, RGB(1.f));
  SceneView residual = scene.Build();
  ASSERT_NE(residual.majorants.grid.minorants, nullptr);
  SceneView plain = residual;
  plain.majorants.grid.minorants = nullptr;
  const Ray ray{{-1.f, 2.f, 2.f}, {1.f, 0.f, 0.f}};
  // Half the ramp: optical depth 0.5 * 0.2 * 10 = 1, so that roulette
  // (below a transmittance of 0.1) plays little part.
  const double expected = std::exp(-1.0);
  TraceCounters plainCounters, residualCounters;
  Estimate p = RatioTransmittance(plain, ray, 1.f + 10.f, 1.f, &plainCounters);
  Estimate r = RatioTransmittance(residual, ray, 1.f + 10.f, 1.f, &residualCounters);
  test::ExpectUnbiased(p.mean, p.standardError, expected, "half ramp, plain ratio tracking");
  test::ExpectUnbiased(r.mean, r.standardError, expected, "half ramp, residual ratio tracking");
  EXPECT_LT(r.standardError, 0.5 * p.standardError);
  // (Measured: 0.40 times the standard error, 0.51 times the lookups.)
  EXPECT_LT(residualCounters.densityLookups, plainCounters.densityLookups * 6 / 10);
}

TEST(Tracking, ObliqueRayInRotatedVolume) {
  // The volume's world matrix rotates it 90 degrees about z; a diagonal ray
  // crosses it in world space; delta tracking must match the analytic depth.
  HostVolume v = test::MakeConstantVolume(11, 1.f, 1.f);
  v.indexToWorld = IndexToWorld({10, 0, 0}, {1, 1, 1}, {0, -1, 0, 1, 0, 0, 0, 0, 1});  // x_world = 10 - j
  Scene scene = test::MakeMediumScene(std::move(v), 0.1f, RGB(1.f));
  SceneView s = scene.Build();
  const Vec3 d = Normalize(Vec3{1.f, 1.f, 0.f});
  const Ray ray{Vec3{0.f, 0.f, 5.f} - d * 3.f, d};  // enters at (0,0,5), leaves at (10,10,5)
  const double expected = std::exp(-0.1 * 10.0 * std::sqrt(2.0));
  Estimate e = DeltaTransmittance(s, ray, kInfinity);
  test::ExpectUnbiased(e.mean, e.standardError, expected, "oblique ray, delta tracking");
}

TEST(Tracking, RayMarchingApproximatesAHomogeneousSlab) {
  // The biased baseline is close to Beer-Lambert where the medium is smooth.
  Scene scene = test::MakeMediumScene(test::MakeConstantVolume(33, 1.f, 0.5f), 0.15f, RGB(1.f));
  scene.render.integrator.rayMarchStep = 0.25f;
  SceneView s = scene.Build();
  PCG32 rng(5, 6);
  TraceCounters ctr;
  double sum = 0;
  const Ray ray{{-5.f, 8.f, 8.f}, {1.f, 0.f, 0.f}};
  for (int i = 0; i < 20000; ++i) sum += RayMarchTransmittance(s, ray, kInfinity, 1.f, rng, ctr);
  EXPECT_NEAR(sum / 20000, std::exp(-0.15 * 16.0), 0.01);
}

}  // namespace
}  // namespace mmrtm
