// The denoised display's inputs, gathered with the samples
// (FilmView::denoiserInputs, Film::DenoiserImages): the radiance is the same
// to the bit with them kept or not;
// where camera rays first collide with a dense slab the albedo guide is the
// material's and the normal faces the camera; where they escape the guide
// is the background, clamped, and no normal; the two halves are the even
// and the odd samples' means; the same images at any thread count.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSceneHelpers.h"
#include "cpu_renderer.h"
#include "film.h"

namespace mmrtm {
namespace {

// Value 1 where y >= 8 (index), 0 before: seen from the default anterior
// camera (looking along +y), a dense face across the middle of the image.
Scene MakeSlabScene(RGB background) {
  Scene scene = test::MakeMediumScene(test::MakeVolume(16, 16, 16, [](int, int j, int) { return j >= 8 ? 1.f : 0.f; }),
                                      50.f, RGB(0.9f, 0.7f, 0.5f));
  scene.environment = EnvironmentMap::Constant(background);
  scene.render.width = scene.render.height = 32;
  return scene;
}

Film Render(const Scene& scene, int spp, bool inputs, int threads = 1) {
  const SceneView view = const_cast<Scene&>(scene).Build();
  Film film(scene.render.width, scene.render.height);
  if (inputs) film.TrackDenoiserInputs();
  CpuRenderer(threads).Render(view, film, spp);
  return film;
}

void ExpectSameRadiance(const Film& a, const Film& b) {
  const NoiseEstimate na = a.Noise(), nb = b.Noise();
  EXPECT_EQ(na.rmsStandardError, nb.rmsStandardError);
  for (int y = 0; y < a.Height(); ++y)
    for (int x = 0; x < a.Width(); ++x)
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(a.Mean(x, y)[c], b.Mean(x, y)[c]) << x << ", " << y;
        ASSERT_EQ(a.VarianceOfMean(x, y)[c], b.VarianceOfMean(x, y)[c]) << x << ", " << y;
      }
}

TEST(DenoiserInputs, TheRadianceIsTheSameToTheBitWithThemOrWithout) {
  Scene lit = test::MakeLitSurfaceScene(test::MakeVolume(12, 12, 12, [](int i, int j, int k) {
    return std::sin(0.7f * i) * std::cos(0.5f * j) + 0.2f * k > 0.3f ? 1.f : 0.f;
  }));
  lit.render.width = lit.render.height = 24;
  ExpectSameRadiance(Render(lit, 6, false), Render(lit, 6, true));
}

TEST(DenoiserInputs, AlbedoAndFaceNormalOnASlabAndTheBackgroundBeside) {
  Scene scene = MakeSlabScene(RGB(2.f, 0.5f, 0.25f));
  const FilmHalves h = Render(scene, 8, true).DenoiserImages();
  ASSERT_EQ(h.albedoWhole.width, 32);
  ASSERT_EQ(h.normalWhole.pixels.size(), 32u * 32u);
  EXPECT_EQ(h.samples[0], 4u);
  EXPECT_EQ(h.samples[1], 4u);
  // The image's centre sees the slab's face head-on.
  for (const RGBImage* albedo : {&h.albedoWhole, &h.albedo[0], &h.albedo[1]}) {
    const RGB a = albedo->pixels[16 * 32 + 16];
    EXPECT_NEAR(a.r, 0.9f, 1e-5f);
    EXPECT_NEAR(a.g, 0.7f, 1e-5f);
    EXPECT_NEAR(a.b, 0.5f, 1e-5f);
  }
  const RGB normal = h.normalWhole.pixels[16 * 32 + 16];
  EXPECT_NEAR(normal.g, -1.f, 0.02f) << "the face's normal, toward the camera (-y)";
  EXPECT_NEAR(std::hypot(normal.r, normal.b), 0.f, 0.1f);
  // The corner sees past the volume: the background, clamped, no normal.
  const RGB bg = h.albedoWhole.pixels[0], none = h.normalWhole.pixels[0];
  EXPECT_EQ(bg.r, 1.f);
  EXPECT_EQ(bg.g, 0.5f);
  EXPECT_EQ(bg.b, 0.25f);
  EXPECT_TRUE(none.IsBlack());

  // A hidden background shows nothing.
  scene.render.integrator.backgroundVisible = false;
  EXPECT_TRUE(Render(scene, 2, true).DenoiserImages().albedoWhole.pixels[0].IsBlack());
}

TEST(DenoiserInputs, TheHalvesAreTheEvenAndTheOddSamples) {
  Scene scene = test::MakeLitSurfaceScene(test::MakeConstantVolume(12, 0.4f));
  scene.render.width = scene.render.height = 16;
  // Sample indices 0..4 in one film; 0, 2, 4 are its even half. The same
  // samples one at a time, in films of their own, give each sample alone.
  const Film film = Render(scene, 5, true);
  const FilmHalves h = film.DenoiserImages();
  EXPECT_EQ(h.samples[0], 3u);
  EXPECT_EQ(h.samples[1], 2u);
  const SceneView view = scene.Build();
  std::vector<Film> single;
  Film growing(16, 16);
  for (int n = 0; n < 5; ++n) {
    CpuRenderer(1).Render(view, growing, 1);
    single.push_back(growing);
  }
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) {
        // The running means: sample n alone is n m_n - (n - 1) m_(n-1).
        auto sample = [&](int n) {
          return n == 0 ? single[0].Mean(x, y)[c] : (n + 1) * single[n].Mean(x, y)[c] - n * single[n - 1].Mean(x, y)[c];
        };
        const float even = (sample(0) + sample(2) + sample(4)) / 3.f, odd = (sample(1) + sample(3)) / 2.f;
        const size_t i = (size_t)y * 16 + x;
        EXPECT_NEAR(h.color[0].pixels[i][c], even, 1e-4f * (1.f + std::abs(even)));
        EXPECT_NEAR(h.color[1].pixels[i][c], odd, 1e-4f * (1.f + std::abs(odd)));
      }
}

TEST(DenoiserInputs, SameImagesAtAnyThreadCount) {
  const Scene scene = MakeSlabScene(RGB(0.3f));
  const FilmHalves one = Render(scene, 4, true, 1).DenoiserImages(), two = Render(scene, 4, true, 2).DenoiserImages();
  for (size_t i = 0; i < one.albedoWhole.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(one.albedoWhole.pixels[i][c], two.albedoWhole.pixels[i][c]) << "pixel " << i;
      ASSERT_EQ(one.normal[1].pixels[i][c], two.normal[1].pixels[i][c]) << "pixel " << i;
      ASSERT_EQ(one.color[0].pixels[i][c], two.color[0].pixels[i][c]) << "pixel " << i;
    }
}

TEST(DenoiserInputs, HalvesNeedTwoSamplesAndTheInputsKept) {
  const Scene scene = MakeSlabScene(RGB(0.3f));
  EXPECT_THROW(Render(scene, 1, true).DenoiserImages(), std::logic_error);
  EXPECT_THROW(Render(scene, 2, false).DenoiserImages(), std::logic_error);
}

}  // namespace
}  // namespace mmrtm
