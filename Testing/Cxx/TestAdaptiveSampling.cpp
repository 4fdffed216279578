// Adaptive sampling (adaptive_sampling.h, CpuRenderer::RenderTo): per-pixel
// sample counts in the film, the split of a budget by the pilot's weights,
// images that depend only on the counts (not on threads or passes), and
// agreement with uniform sampling within noise (it is unbiased).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>

#include "ExpectAgreement.h"
#include "ReplicateRenders.h"
#include "TestSceneHelpers.h"
#include "adaptive_sampling.h"
#include "cpu_renderer.h"

namespace mmrtm {
namespace {

Scene MakeScene() {
  Scene scene =
      test::MakeMediumScene(test::MakeVolume(12, 12, 12, [](int i, int j, int k) { return (i * j + k) % 5 / 4.f; }),
                            1.f, RGB(0.9f, 0.7f, 0.5f), 0.3f);
  scene.materials[0].base[6] = 0.5f;
  scene.environment = EnvironmentMap::DefaultSky();
  scene.render.integrator.shadowExtinctionScale = 1.f;
  scene.render.integrator.seed = 3;
  return scene;
}

std::vector<float> Pixels(const Film& film) {
  std::vector<float> out;
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      const RGB c = film.Mean(x, y);
      out.insert(out.end(), {c.r, c.g, c.b, film.Alpha(x, y)});
    }
  return out;
}

TEST(AdaptiveFilm, PerPixelCountsGiveEachPixelItsOwnVariance) {
  Film film(2, 1);
  FilmView view = film.View();
  // Pixel 0: samples 1, 3 (variance of the mean 1); pixel 1: 1, 3, 1, 3 (1/3).
  for (uint32_t n = 1; n <= 2; ++n) view.AddSample(0, 0, RGB(n == 1 ? 1.f : 3.f), 1.f, n);
  for (uint32_t n = 1; n <= 4; ++n) view.AddSample(1, 0, RGB(n % 2 ? 1.f : 3.f), 1.f, n);
  EXPECT_FALSE(film.Adaptive());
  film.SetPixelSamples({2, 4});
  EXPECT_TRUE(film.Adaptive());
  EXPECT_EQ(film.Samples(), 2u) << "the count every pixel has";
  EXPECT_EQ(film.MaxSamples(), 4u);
  EXPECT_DOUBLE_EQ(film.MeanSamples(), 3.0);
  EXPECT_NEAR(film.VarianceOfMean(0, 0).g, 1.f, 1e-6f);
  EXPECT_NEAR(film.VarianceOfMean(1, 0).g, 1.f / 3.f, 1e-6f);
  EXPECT_THROW(film.Moments(), std::logic_error) << "moments without counts would combine wrongly";
  EXPECT_THROW(film.SetPixelSamples({1, 2, 3}), std::invalid_argument);
  film.AddSamples(1);
  EXPECT_EQ(film.PixelSamples(1, 0), 5u);
  film.Reset();
  EXPECT_FALSE(film.Adaptive());
  EXPECT_EQ(film.Samples(), 0u);
}

TEST(AdaptiveSampling, WeightsComeFromTheNeighboursOnly) {
  // One noisy pixel in a noiseless pilot: its own weight stays 0 (its count
  // must not depend on its own samples), its eight neighbours get weight.
  Film pilot(5, 5);
  FilmView view = pilot.View();
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x)
      for (uint32_t n = 1; n <= 4; ++n) view.AddSample(x, y, RGB(x == 2 && y == 2 ? (float)(n % 2) : 0.5f), 1.f, n);
  pilot.AddSamples(4);
  const std::vector<float> w = AdaptiveSampleWeights(pilot);
  EXPECT_EQ(w[2 * 5 + 2], 0.f);
  for (int y = 1; y <= 3; ++y)
    for (int x = 1; x <= 3; ++x)
      if (x != 2 || y != 2) EXPECT_GT(w[y * 5 + x], 0.f) << x << ", " << y;
  EXPECT_EQ(w[0], 0.f) << "no noisy neighbour";
  Film one(5, 5);
  one.AddSamples(1);
  EXPECT_THROW(AdaptiveSampleWeights(one), std::invalid_argument) << "one sample gives no variance";
}

TEST(AdaptiveSampling, CountsSplitTheBudgetByWeight) {
  Film film(100, 1);
  film.AddSamples(4);
  std::vector<float> w(100, 0.f);
  for (int i = 0; i < 10; ++i) w[i] = 1.f;  // ten noisy pixels
  w[10] = 3.f;                              // one three times as noisy
  const std::vector<uint32_t> counts = AdaptiveSampleCounts(film, w, 16.0, 1000);
  const double mean = std::accumulate(counts.begin(), counts.end(), 0.0) / 100.0;
  EXPECT_NEAR(mean, 16.0, 0.2);
  for (int i = 11; i < 100; ++i) EXPECT_EQ(counts[i], 4u) << "never below the pilot";
  EXPECT_NEAR((double)counts[10] / counts[0], 3.0, 0.1);
  // The cap holds, and the rest of the budget is not forced elsewhere.
  const std::vector<uint32_t> capped = AdaptiveSampleCounts(film, w, 16.0, 40);
  EXPECT_EQ(*std::max_element(capped.begin(), capped.end()), 40u);
  // A noiseless pilot: the budget spread uniformly.
  const std::vector<uint32_t> flat = AdaptiveSampleCounts(film, std::vector<float>(100, 0.f), 16.0, 1000);
  for (uint32_t c : flat) EXPECT_EQ(c, 16u);
}

TEST(AdaptiveSampling, ImageDependsOnlyOnTheCounts) {
  Scene scene = MakeScene();  // the view points into it: it must outlive the renders
  const SceneView view = scene.Build();
  std::vector<uint32_t> half(37 * 23), full(37 * 23);
  for (size_t i = 0; i < full.size(); ++i) {
    full[i] = 4 + (uint32_t)(i * 7 % 13);
    half[i] = 4 + (full[i] - 4) / 2;
  }
  Film a(37, 23), b(37, 23);  // not a multiple of the tile size
  CpuRenderer(1).Render(view, a, 4);
  CpuRenderer(1).RenderTo(view, a, full);
  CpuRenderer(2).Render(view, b, 4);
  CpuRenderer(2).RenderTo(view, b, half);
  CpuRenderer(2).RenderTo(view, b, full);
  EXPECT_EQ(Pixels(a), Pixels(b)) << "one thread in one pass, two threads in two passes: the same bits";
  EXPECT_EQ(a.PixelSamples(5, 3), full[3 * 37 + 5]);
  // Uniform targets equal a uniform render.
  Film c(37, 23), d(37, 23);
  CpuRenderer(2).Render(view, c, 9);
  CpuRenderer(2).RenderTo(view, d, std::vector<uint32_t>(37 * 23, 9));
  EXPECT_EQ(Pixels(c), Pixels(d));
  EXPECT_THROW(CpuRenderer(2).RenderTo(view, d, std::vector<uint32_t>(5, 9)), std::invalid_argument);
}

// Adaptive sampling is unbiased: 8 replicates of it (each a pilot of 8
// samples, then 24 a pixel on average where the pilot's neighbours are
// noisy) against 8 uniform replicates of 24 samples (ImageAgreement.h: two
// unbiased estimates fail with probability below 1e-4; the power, a change
// of a channel's covered-pixel mean that fails with probability 1 - 1e-4,
// is asserted at most 2 % and shown by the adaptive image made 2 % darker).
TEST(AdaptiveSampling, AgreesWithUniformSamplingWithinNoise) {
  Scene scene = MakeScene();
  scene.render.width = scene.render.height = 32;
  const SceneView view = scene.Build();
  const test::ImageEstimate uniform = test::RenderReplicates(view, 8, 24, 100);
  uint32_t fewest = ~0u, most = 0;
  const test::ImageEstimate adaptive = test::EstimateFromReplicates(8, 200, [&](uint64_t seed) {
    SceneView v = view;
    v.settings.seed = seed;
    Film film(32, 32);
    film.TrackWork();
    CpuRenderer(2).Render(v, film, 8);
    CpuRenderer(2).RenderTo(v, film, AdaptiveSampleCounts(film, AdaptiveSampleWeights(film), 24.0, 16 * 24));
    fewest = std::min(fewest, film.Samples());
    most = std::max(most, film.MaxSamples());
    return film;
  });
  EXPECT_GT(most, 2 * fewest) << "the counts differ from pixel to pixel";
  test::ExpectAgreement("uniform / adaptive", uniform, adaptive);
  test::ExpectDisagreement("uniform / adaptive 2 % darker", uniform, test::Scaled(adaptive, 0.98));
  double luminance = 0;
  for (double m : uniform.mean) luminance += m / uniform.mean.size();
  EXPECT_GT(luminance, 0.05) << "a dark image proves nothing";
}

}  // namespace
}  // namespace mmrtm
