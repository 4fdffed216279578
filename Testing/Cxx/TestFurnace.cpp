// Furnace tests: a non-absorbing medium (albedo 1) under a uniform
// environment must return exactly the environment's radiance, whatever its
// density, phase function or path length: every path ends in the environment
// with throughput 1 (in expectation). Any energy gain or loss in tracking,
// next-event estimation, MIS or Russian roulette shows up here.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSceneHelpers.h"
#include "cpu_renderer.h"

namespace mmrtm {
namespace {

struct FurnaceCase {
  float density;  // sigma_t per mm; the box is 15 mm wide
  float g;
  bool heterogeneous;
};

class Furnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(Furnace, ReturnsTheEnvironmentRadiance) {
  const FurnaceCase c = GetParam();
  const RGB environment(0.5f, 0.5f, 0.5f);
  HostVolume volume = c.heterogeneous
                          ? test::MakeVolume(16, 16, 16, [](int i, int j, int k) { return ((i + j + k) % 3) / 2.f; })
                          : test::MakeConstantVolume(16, 1.f);
  Scene scene = test::MakeMediumScene(std::move(volume), c.density, RGB(1.f), c.g);
  scene.environment = EnvironmentMap::Constant(environment);
  scene.render.width = scene.render.height = 8;
  scene.render.integrator.maxBounces = 100000;  // only Russian roulette ends paths
  scene.camera.zoom = 2.f;                      // every pixel sees the medium
  SceneView view = scene.Build();

  Film film(8, 8);
  CpuRenderer(2).Render(view, film, 512);
  // Every pixel is an independent estimate of the same value: test the mean
  // over pixels against the standard error from the per-pixel variances.
  double sum = 0, variance = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      sum += film.Mean(x, y).g;
      variance += film.VarianceOfMean(x, y).g;
    }
  const double mean = sum / 64, sigma = std::sqrt(variance) / 64;
  EXPECT_GT(sigma, 0.0);
  EXPECT_NEAR(mean, 0.5, 3 * sigma) << "density " << c.density << " g " << c.g;
}

INSTANTIATE_TEST_SUITE_P(Media, Furnace,
                         ::testing::Values(FurnaceCase{0.3f, 0.f, false}, FurnaceCase{2.f, 0.f, false},
                                           FurnaceCase{1.f, 0.8f, false}, FurnaceCase{1.f, -0.5f, false},
                                           FurnaceCase{1.5f, 0.3f, true}));

}  // namespace
}  // namespace mmrtm
