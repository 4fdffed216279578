// DESIGN.md rule 2: the same seed and sample count give the same image to
// the last bit at any thread count; another seed gives another image.
#include <gtest/gtest.h>

#include <cstring>

#include "TestSceneHelpers.h"
#include "cpu_renderer.h"

namespace mmrtm {
namespace {

// `forceGeneral`: classify as if the scene were not plain (Classifier::plain off).
std::vector<float> Render(Scene& scene, int threads, uint64_t seed, int passes, bool forceGeneral = false) {
  scene.render.integrator.seed = seed;
  SceneView view = scene.Build();
  if (forceGeneral) view.classifier.plain = false;
  Film film(37, 23);  // not a multiple of the tile size
  for (int p = 0; p < passes; ++p) CpuRenderer(threads).Render(view, film, 8 / passes);
  std::vector<float> pixels;
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      RGB c = film.Mean(x, y);
      pixels.insert(pixels.end(), {c.r, c.g, c.b, film.Alpha(x, y)});
    }
  return pixels;
}

Scene MakeScene() {
  return test::MakeLitSurfaceScene(
      test::MakeVolume(12, 12, 12, [](int i, int j, int k) { return (i * j + k) % 5 / 4.f; }));
}

TEST(Determinism, ThreadCountDoesNotChangeTheImage) {
  Scene scene = MakeScene();
  std::vector<float> one = Render(scene, 1, 42, 1), two = Render(scene, 2, 42, 1), five = Render(scene, 5, 42, 1);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(0, std::memcmp(one.data(), two.data(), one.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(one.data(), five.data(), one.size() * sizeof(float)));
  double sum = 0;
  for (float v : one) sum += v;
  EXPECT_GT(sum, 0.0) << "a black image proves nothing";
}

TEST(Determinism, PlainScenePathEqualsTheGeneralPath) {
  // A plain scene (one proxy, one material, one density TF) takes the
  // classifier's shortest path; it must compute exactly what the general
  // path computes.
  Scene scene = MakeScene();
  ASSERT_TRUE(scene.Build().classifier.plain);
  std::vector<float> shortest = Render(scene, 2, 9, 1), general = Render(scene, 2, 9, 1, true);
  EXPECT_EQ(0, std::memcmp(shortest.data(), general.data(), shortest.size() * sizeof(float)));
  // A second material, chosen by an MDPTF over a label proxy, makes it not plain.
  Scene labelled = MakeScene();
  test::AddLabelledSecondMaterial(labelled);
  EXPECT_FALSE(labelled.Build().classifier.plain);
}

TEST(Determinism, ProgressivePassesEqualOneRender) {
  Scene scene = MakeScene();
  std::vector<float> once = Render(scene, 2, 7, 1), inTwo = Render(scene, 2, 7, 2);
  // Same sample indices, same per-pixel order of accumulation: the same bits.
  EXPECT_EQ(0, std::memcmp(once.data(), inTwo.data(), once.size() * sizeof(float)));
}

TEST(Determinism, AnotherSeedGivesAnotherImage) {
  Scene scene = MakeScene();
  std::vector<float> a = Render(scene, 2, 1, 1), b = Render(scene, 2, 2, 1);
  size_t differing = 0;  // pixels whose colour differs (alpha is often 0 or 1 in both)
  for (size_t i = 0; i < a.size(); i += 4) differing += a[i] != b[i] || a[i + 1] != b[i + 1] || a[i + 2] != b[i + 2];
  EXPECT_GT(differing, a.size() / 4 / 2);
}

}  // namespace
}  // namespace mmrtm

namespace mmrtm {
namespace {

// Camera rays stop at cameraRayMaxDistance (opaque geometry of the host
// application): a limit at the camera leaves the image empty and
// transparent, a limit beyond the volume changes nothing, and a limit in
// the middle of the volume lowers the coverage.
TEST(CameraRayLimit, StopsCameraRaysOnly) {
  Scene scene = MakeScene();
  scene.render.width = 37;
  scene.render.height = 23;
  // A finite limit means geometry stands there and hides the background; with
  // the background hidden anyway (as in the VTK mapper), a far limit is no limit.
  scene.render.integrator.backgroundVisible = false;
  const std::vector<float> free = Render(scene, 2, 5, 1);
  scene.cameraRayMaxDistance.assign(37 * 23, 1e6f);
  EXPECT_EQ(Render(scene, 2, 5, 1), free) << "a limit beyond the volume changes nothing";
  scene.cameraRayMaxDistance.assign(37 * 23, 1e-4f);
  for (float v : Render(scene, 2, 5, 1)) EXPECT_EQ(v, 0.f) << "geometry at the camera hides everything";
  double coverageFree = 0, coverageHalf = 0;
  for (size_t i = 3; i < free.size(); i += 4) coverageFree += free[i];
  ASSERT_GT(coverageFree, 0.0);
  scene.camera.autoFrame = true;
  const SceneView view = scene.Build();
  // Half way: the distance from the camera to the volume's centre.
  const float half = Length(scene.proxies[0].WorldCenter() - view.camera.position);
  scene.cameraRayMaxDistance.assign(37 * 23, half);
  const std::vector<float> halfImage = Render(scene, 2, 5, 1);
  for (size_t i = 3; i < halfImage.size(); i += 4) coverageHalf += halfImage[i];
  EXPECT_GT(coverageHalf, 0.0);
  EXPECT_LT(coverageHalf, coverageFree - 1.0) << "geometry in the middle hides what lies behind it";
  scene.cameraRayMaxDistance.assign(5, 1.f);
  EXPECT_THROW(scene.Build(), InputError) << "a limit of the wrong size";
}

}  // namespace
}  // namespace mmrtm

namespace mmrtm {
namespace {

// Clip planes keep one side: the image of the kept half is the image of the
// whole volume where that half is all the camera sees, and nothing elsewhere.
TEST(ClipPlanes, KeepOneSide) {
  Scene scene = MakeScene();
  scene.render.integrator.backgroundVisible = false;
  scene.camera.autoFrame = true;  // looks along +y: world x runs across the image
  const Vec3 c = scene.proxies[0].WorldCenter();
  const std::vector<float> whole = Render(scene, 2, 5, 1);
  scene.clipPlanes = {ClipPlane{Vec3{1.f, 0.f, 0.f}, -c.x}};  // keep x >= centre
  const std::vector<float> half = Render(scene, 2, 5, 1);
  double left = 0, right = 0, wholeLeft = 0, wholeRight = 0;
  for (int y = 0; y < 23; ++y)
    for (int x = 0; x < 37; ++x) {
      const size_t a = 4 * (size_t)(y * 37 + x) + 3;
      (x < 16 ? left : right) += half[a];
      (x < 16 ? wholeLeft : wholeRight) += whole[a];
    }
  ASSERT_GT(wholeLeft, 1.0);
  ASSERT_GT(wholeRight, 1.0);
  // One half of the image is empty, the other keeps most of its coverage.
  EXPECT_LT(std::min(left, right), 0.05 * std::min(wholeLeft, wholeRight));
  EXPECT_GT(std::max(left, right), 0.5 * std::max(wholeLeft, wholeRight));
  // A plane that keeps everything changes nothing; one that keeps nothing empties the image.
  scene.clipPlanes = {ClipPlane{Vec3{1.f, 0.f, 0.f}, 1e6f}};
  EXPECT_EQ(Render(scene, 2, 5, 1), whole);
  scene.clipPlanes = {ClipPlane{Vec3{1.f, 0.f, 0.f}, -1e6f}};
  for (float v : Render(scene, 2, 5, 1)) EXPECT_EQ(v, 0.f);
}

}  // namespace
}  // namespace mmrtm
