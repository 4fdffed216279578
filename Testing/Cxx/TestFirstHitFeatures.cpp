// The denoised preview's guide images (mmrtm/first_hit_features.h,
// cpu/feature_pass.h): where camera rays first collide with a dense slab,
// the material's albedo and the slab's face normal turned toward the
// camera; where they escape, the background (clamped to [0, 1]) and no
// normal; the same images at any thread count. (That the radiance image
// is the same with or without a preview: test_mmrtm_render_cli.py.)
#include <gtest/gtest.h>

#include <cmath>

#include "TestSceneHelpers.h"
#include "feature_pass.h"

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

TEST(FirstHitFeatures, AlbedoAndFaceNormalOnASlabAndTheBackgroundBeside) {
  Scene scene = MakeSlabScene(RGB(2.f, 0.5f, 0.25f));
  const SceneView view = scene.Build();
  const FeatureImages f = RenderFeatureImages(view, 8, 1);
  ASSERT_EQ(f.albedo.width, 32);
  ASSERT_EQ(f.normal.pixels.size(), 32u * 32u);
  // The image's centre sees the slab's face head-on.
  const RGB albedo = f.albedo.pixels[16 * 32 + 16], normal = f.normal.pixels[16 * 32 + 16];
  EXPECT_NEAR(albedo.r, 0.9f, 1e-5f);
  EXPECT_NEAR(albedo.g, 0.7f, 1e-5f);
  EXPECT_NEAR(albedo.b, 0.5f, 1e-5f);
  EXPECT_NEAR(normal.g, -1.f, 0.02f) << "the face's normal, toward the camera (-y)";
  EXPECT_NEAR(std::hypot(normal.r, normal.b), 0.f, 0.1f);
  // The corner sees past the volume: the background, clamped, no normal.
  const RGB bg = f.albedo.pixels[0], none = f.normal.pixels[0];
  EXPECT_EQ(bg.r, 1.f);
  EXPECT_EQ(bg.g, 0.5f);
  EXPECT_EQ(bg.b, 0.25f);
  EXPECT_EQ(none.r, 0.f);
  EXPECT_EQ(none.g, 0.f);
  EXPECT_EQ(none.b, 0.f);

  // A hidden background shows nothing.
  scene.render.integrator.backgroundVisible = false;
  const SceneView hidden = scene.Build();
  EXPECT_TRUE(RenderFeatureImages(hidden, 2, 1).albedo.pixels[0].IsBlack());
}

TEST(FirstHitFeatures, SameImagesAtAnyThreadCount) {
  Scene scene = MakeSlabScene(RGB(0.3f));
  const SceneView view = scene.Build();
  const FeatureImages one = RenderFeatureImages(view, 4, 1), two = RenderFeatureImages(view, 4, 2);
  ASSERT_EQ(one.albedo.pixels.size(), two.albedo.pixels.size());
  for (size_t i = 0; i < one.albedo.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(one.albedo.pixels[i][c], two.albedo.pixels[i][c]) << "pixel " << i;
      ASSERT_EQ(one.normal.pixels[i][c], two.normal.pixels[i][c]) << "pixel " << i;
    }
}

}  // namespace
}  // namespace mmrtm
