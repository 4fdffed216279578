// The CPU's SIMD backend (--simd on: a tile's camera rays delta-tracked in
// SIMD lanes; cpu/wavefront_camera_paths.h)
// against the scalar backend (--simd off): the same image to the last bit,
// scene feature by feature, on every instruction set this machine runs.
//
// What it catches: any difference at all between the two, which is more
// than a statistical test can (Documentation/decisions.md: the lanes round
// as the scalar code does). A path whose random numbers are drawn in
// another order, a lookup or a step of the majorant walk that rounds or
// decides differently (the lanes' walk mirrors GridMajorantIterator: a
// change to one that the other misses), an arrival lost at a batch's end,
// a sample added to another pixel or in another order, a feature the
// wavefront forgets (clipping, depth compositing, the Sobol' pair of the
// first arrival) each change bits. Planted and seen failing:
// the lanes' extinction x0.98 (the planted defect simd_extinction), the
// first arrival's Sobol' pair ignored, the batch of 1024 paths made 1000
// (pixels then straddle batches; still equal: the order is kept).
// The statistical comparison of the two backends on the five reference
// scenes is Testing/Accuracy/test_simd_backend.py; the failure-case scenes
// (FailureCaseScenes.h) are compared here, to the bit.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "FailureCaseScenes.h"
#include "TestSceneHelpers.h"
#include "TestTypedVolumes.h"
#include "cpu_renderer.h"
#include "plain_extinction.h"
#include "simd_targets.h"

namespace mmrtm {
namespace {

struct Image {
  std::vector<float> pixels;  // mean RGB, alpha, per-pixel work, per pixel
  LaneCounters lanes;
};

// `adaptive`: a uniform pass then per-pixel targets (RenderTo), as
// adaptive sampling renders.
Image Render(const SceneView& view, SimdMode simd, int threads = 2, int spp = 7, bool adaptive = false) {
  Film film(37, 23);  // not a multiple of the tile size
  film.TrackWork();
  CpuRenderer renderer(threads, simd);
  Image image;
  renderer.CountLanes(&image.lanes);
  renderer.Render(view, film, spp);
  if (adaptive) {
    std::vector<uint32_t> targets((size_t)film.Width() * film.Height());
    for (size_t i = 0; i < targets.size(); ++i) targets[i] = (uint32_t)(spp + i % 5);
    renderer.RenderTo(view, film, targets);
  }
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      const RGB c = film.Mean(x, y);
      image.pixels.insert(image.pixels.end(), {c.r, c.g, c.b, film.Alpha(x, y), film.Work(x, y)});
    }
  return image;
}

double Sum(const Image& image) {
  double sum = 0;
  for (size_t i = 0; i < image.pixels.size(); i += 5) sum += image.pixels[i] + image.pixels[i + 1];
  return sum;
}

// TestDeterminism's lit scene, at Render's film size.
Scene MakeScene(HostVolume volume) {
  Scene scene = test::MakeLitSurfaceScene(std::move(volume));
  scene.render.width = 37;
  scene.render.height = 23;
  return scene;
}

float Pattern(int i, int j, int k) { return (float)((i * j + k) % 5) / 4.f; }

Scene MakeFloatScene() { return MakeScene(test::MakeVolume(12, 12, 12, Pattern)); }

// Expects the SIMD backend's image to be the scalar one's, bit for bit, and
// neither to be black; returns the SIMD render.
Image ExpectSameImage(const SceneView& view, const std::string& what, int spp = 7, bool adaptive = false) {
  const Image scalar = Render(view, SimdMode::Off, 2, spp, adaptive);
  const Image simd = Render(view, SimdMode::On, 2, spp, adaptive);
  EXPECT_GT(Sum(scalar), 0.0) << what << ": a black image proves nothing";
  EXPECT_EQ(scalar.lanes.actions, 0u) << what << ": --simd off ran lanes";
  EXPECT_EQ(CpuRenderer(2, SimdMode::On).UsesSimd(view), simd.lanes.actions > 0) << what;
  EXPECT_EQ(scalar.pixels.size(), simd.pixels.size());
  EXPECT_EQ(0, std::memcmp(scalar.pixels.data(), simd.pixels.data(), scalar.pixels.size() * sizeof(float)))
      << what << ": the SIMD backend's image differs from the scalar one's";
  return simd;
}

TEST(SimdBackend, IsUsedWhereItRuns) {
  Scene scene = MakeFloatScene();
  SceneView view = scene.Build();
  EXPECT_TRUE(CpuRenderer(1, SimdMode::On).UsesSimd(view));
  EXPECT_FALSE(CpuRenderer(1, SimdMode::Off).UsesSimd(view));
  EXPECT_NE(CpuRenderer(1, SimdMode::On).Description().find("SIMD"), std::string::npos);
  EXPECT_NE(CpuRenderer(1, SimdMode::Off).Description().find("scalar"), std::string::npos);
  view.settings.estimator = Estimator::RayMarching;  // not tracked in waves
  EXPECT_FALSE(CpuRenderer(1, SimdMode::On).UsesSimd(view));
  view = scene.Build();
  view.settings.projection.mode = IntensityProjection::Maximum;  // no paths
  EXPECT_FALSE(CpuRenderer(1, SimdMode::On).UsesSimd(view));
  scene.render.accelerator.kind = MajorantKind::Global;  // no grid to walk
  const SceneView global = scene.Build();
  EXPECT_FALSE(CpuRenderer(1, SimdMode::On).UsesSimd(global));
  EXPECT_EQ(ParseSimdMode("auto"), SimdMode::Auto);
  EXPECT_EQ(ParseSimdMode("on"), SimdMode::On);
  EXPECT_EQ(ParseSimdMode("off"), SimdMode::Off);
  EXPECT_FALSE(ParseSimdMode("yes").has_value());
  // The description of a scene says what renders it, whatever the mode asked.
  EXPECT_NE(CpuRenderer(1, SimdMode::On).Description(&global).find("scalar"), std::string::npos);
}

// Auto takes the lanes where they are faster (WavefrontCameraPaths::Faster):
// they start the camera paths too (the Sobol' sampler, a pinhole) and hold
// 8 floats or more; elsewhere the scalar tracker.
TEST(SimdBackend, AutoTakesTheLanesWhereTheyAreFaster) {
  const char* env = std::getenv("MMRTM_CPU_SIMD");
  if (const std::string forced = env ? env : ""; forced == "on" || forced == "off") {
    // The planted-defect check decides auto for a whole run; nothing of
    // auto's own choice to test then (the test runs without it in the suite).
    EXPECT_EQ(CpuRenderer(1, SimdMode::Auto).UsesSimd(MakeFloatScene().Build()), forced == "on");
    return;
  }
  Scene scene = MakeFloatScene();
  const SceneView view = scene.Build();
  Scene independent = MakeFloatScene();
  independent.render.integrator.sampler = PixelSampler::Independent;
  const SceneView independentView = independent.Build();
  SceneView lens = scene.Build();
  lens.camera.lensRadius = 0.5f;
  lens.camera.focusDistance = 20.f;
  for (const SimdTarget& target : AvailableSimdTargets()) {
    ForceSimdTarget(target.bits);
    const bool wide = PlainExtinctionLaneCount() >= 8;
    const CpuRenderer automatic(1, SimdMode::Auto);
    EXPECT_EQ(automatic.UsesSimd(view), wide) << target.name;
    EXPECT_EQ(automatic.Description(&view).find("SIMD") != std::string::npos, wide) << target.name;
    EXPECT_EQ(automatic.Description().find("where faster") != std::string::npos, wide) << target.name;
    EXPECT_FALSE(automatic.UsesSimd(independentView)) << target.name << ": the paths start in scalar code";
    EXPECT_FALSE(automatic.UsesSimd(lens)) << target.name << ": the paths start in scalar code";
    EXPECT_TRUE(CpuRenderer(1, SimdMode::On).UsesSimd(independentView)) << target.name;
  }
  ForceSimdTarget(0);
  // What auto runs is the lanes' image, the scalar one's to the bit
  // (ExpectSameImage's renders are On and Off).
  const Image automatic = Render(view, SimdMode::Auto);
  EXPECT_EQ(0, std::memcmp(automatic.pixels.data(), Render(view, SimdMode::Off).pixels.data(),
                           automatic.pixels.size() * sizeof(float)));
}

TEST(SimdBackend, PlainSceneInLanesOnEveryInstructionSet) {
  Scene scene = MakeFloatScene();
  const SceneView view = scene.Build();
  ASSERT_TRUE(view.classifier.plain);
  const std::vector<SimdTarget> targets = AvailableSimdTargets();
  ASSERT_FALSE(targets.empty());
  for (const SimdTarget& target : targets) {
    ForceSimdTarget(target.bits);
    const Image simd = ExpectSameImage(view, target.name);
    // The lookups ran in lanes, and kept most of them busy.
    EXPECT_GT(simd.lanes.lookups, 1000u) << target.name;
    EXPECT_GT(simd.lanes.WalkOccupancy(), 0.5) << target.name;
  }
  ForceSimdTarget(0);
}

TEST(SimdBackend, EveryVoxelType) {
  const Affine3 grid = test::Grid({0, 0, 0}, {1, 1, 1});
  const auto f = [](int i, int j, int k) { return 100.0 * Pattern(i, j, k); };
  for (HostVolume volume :
       {test::MakeTyped<uint8_t>({12, 11, 10}, f, grid), test::MakeTyped<int16_t>({12, 11, 10}, f, grid),
        test::MakeTyped<uint16_t>({12, 11, 10}, f, grid),
        test::MakeTyped<float>({12, 11, 10}, f, grid, "scalars", Interpolation::Nearest)}) {
    const std::string what = "voxel type " + std::to_string((int)volume.type);
    Scene scene = MakeScene(std::move(volume));
    scene.materials[0].base[0] = 0.01f;  // the TF maps 0..100 to itself
    ExpectSameImage(scene.Build(), what);
  }
}

TEST(SimdBackend, SceneNotPlainWalksInLanesAndClassifiesOnePointAtATime) {
  // A label proxy choosing a second material (as TestDeterminism): the
  // walk runs in lanes, the lookups are the classifier's.
  Scene scene = MakeFloatScene();
  test::AddLabelledSecondMaterial(scene);
  scene.materials[1].base[1] = 0.2f;
  const SceneView view = scene.Build();
  ASSERT_FALSE(view.classifier.plain);
  const Image simd = ExpectSameImage(view, "two materials");
  EXPECT_GT(simd.lanes.actions, 0u);
}

TEST(SimdBackend, ClippingDepthCompositingLensAndCropping) {
  Scene scene = MakeFloatScene();
  scene.clipPlanes.push_back({Normalize(Vec3{1.f, 0.2f, 0.f}), -5.f});
  scene.camera.lensRadius = 0.3f;
  scene.cameraRayMaxDistance.assign(37 * 23, kInfinity);
  for (size_t i = 0; i < scene.cameraRayMaxDistance.size(); i += 3) scene.cameraRayMaxDistance[i] = 20.f + (i % 7);
  ExpectSameImage(scene.Build(), "clip plane, depth buffer, lens");
  scene.cropping.keep = Classifier::kNoCropping & ~(1u << 13);  // all regions but the middle one
  for (int a = 0; a < 3; ++a) {
    scene.cropping.lo[a] = 3.f;
    scene.cropping.hi[a] = 8.f;
  }
  ExpectSameImage(scene.Build(), "cropping");
}

TEST(SimdBackend, SamplersLightSamplingAndMajorants) {
  Scene scene = MakeFloatScene();
  Light point;
  point.type = LightType::Point;
  point.vector = Vec3{20.f, 5.f, 5.f};
  point.L = RGB(50.f);
  scene.lights.push_back(point);
  for (LightSampling mode : {LightSampling::One, LightSampling::All, LightSampling::Resampled})
    for (PixelSampler sampler : {PixelSampler::Sobol, PixelSampler::Independent}) {
      scene.render.integrator.lightSampling = mode;
      scene.render.integrator.sampler = sampler;
      ExpectSameImage(scene.Build(),
                      "light sampling " + std::to_string((int)mode) + ", sampler " + std::to_string((int)sampler));
    }
  for (MajorantKind kind : {MajorantKind::Global, MajorantKind::Macrocell}) {
    scene.render.accelerator.kind = kind;
    ExpectSameImage(scene.Build(), "majorants " + std::to_string((int)kind));
  }
}

TEST(SimdBackend, AdaptiveSamplingAndBatchesThatSplitPixels) {
  // 7 samples a pixel do not divide a batch of 1024 paths: pixels straddle
  // batches; RenderTo continues each pixel from its own count.
  Scene scene = MakeFloatScene();
  ExpectSameImage(scene.Build(), "adaptive", 7, true);
  ExpectSameImage(scene.Build(), "many samples", 61);
}

TEST(SimdBackend, FailureCaseScenes) {
  // The scenes where trackers fail (TestFailureCases): a TF peak narrower
  // than a voxel, a sparse block, a sheet on a node face, a step at the
  // data maximum, all-zero and all-one TFs; on both grids.
  for (MajorantKind kind : {MajorantKind::Octree, MajorantKind::Macrocell}) {
    std::vector<std::pair<std::string, failure::Case>> cases;
    cases.emplace_back("narrow peak", failure::NarrowPeak(0.05f, 40.f, kind, SummaryMode::CellRanges));
    cases.emplace_back("sparse block", failure::SparseBlock(32, 2.f, kind));
    cases.emplace_back("sheet on a node face", failure::SliceSheet(16.f, 1.f, kind, 0.3f));
    cases.emplace_back("saturated block", failure::SaturatedBlock(2.f, kind));
    cases.emplace_back("all-zero TF", failure::AllZeroTF(kind));
    cases.emplace_back("all-one TF", failure::AllOneTF(kind));
    for (auto& [name, c] : cases) {
      c.scene.environment = EnvironmentMap::DefaultSky();
      ExpectSameImage(c.scene.Build(), name + (kind == MajorantKind::Octree ? ", octree" : ", macrocell"));
    }
  }
}

TEST(SimdBackend, SameImageAtAnyThreadCount) {
  Scene scene = MakeFloatScene();
  const SceneView view = scene.Build();
  const Image one = Render(view, SimdMode::On, 1), three = Render(view, SimdMode::On, 3);
  EXPECT_EQ(0, std::memcmp(one.pixels.data(), three.pixels.data(), one.pixels.size() * sizeof(float)));
  EXPECT_EQ(one.lanes.lookups, three.lanes.lookups);
}

}  // namespace
}  // namespace mmrtm
