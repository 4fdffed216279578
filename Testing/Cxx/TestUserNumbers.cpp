// Numbers from users that the tracer must survive (Documentation/reliability.md):
// extinctions far beyond anything physical (a density of 1e30, VTK's opacity
// over a unit distance near 0) are clamped to an optical depth of
// kMaxOpticalDepthPerVoxel per voxel with a warning, so that a ray's null
// collisions stay bounded; a density of 0 is an empty volume; and no image
// holds a value that is not finite. (Bad numbers in files and scene
// documents are errors: TestVolumeLoader, the fuzz replays.)
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "cpu_renderer.h"
#include "film.h"
#include "TestSceneHelpers.h"

namespace mmrtm {
namespace {

struct Rendered {
  Film film{16, 16};
  TraceCounters counters;
  std::string warning;
  float majorant = 0.f;
};

// A 16^3 volume of constant value 1 (unit spacing), one material of
// `density`, 16 x 16 pixels, 4 samples, seed 1.
Rendered RenderConstantMedium(float density) {
  Scene scene = test::MakeMediumScene(test::MakeConstantVolume(16, 1.f), density, RGB(0.8f));
  scene.render.integrator.seed = 1;
  Rendered r;
  const SceneView view = scene.Build();
  r.warning = scene.ExtinctionWarning();
  r.majorant = view.majorants.globalMajorant;
  CpuRenderer(2).Render(view, r.film, 4, &r.counters);
  return r;
}

bool AllFinite(const Film& film) {
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      const RGB c = film.Mean(x, y);
      if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b) || !std::isfinite(film.Alpha(x, y)))
        return false;
    }
  return true;
}

TEST(UserNumbers, HugeDensityIsClampedToTheMaximumOpticalDepthWithAWarning) {
  const float cap = kMaxOpticalDepthPerVoxel;  // per mm at unit spacing
  const Rendered huge = RenderConstantMedium(1e30f), atCap = RenderConstantMedium(cap);
  EXPECT_NE(huge.warning.find("clamped"), std::string::npos) << huge.warning;
  EXPECT_TRUE(atCap.warning.empty()) << atCap.warning;
  EXPECT_EQ(huge.majorant, cap);
  EXPECT_TRUE(AllFinite(huge.film));
  EXPECT_EQ(huge.counters.majorantViolations, 0u);
  // The clamped medium is the medium at the cap: the same image, bit for bit.
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      EXPECT_EQ(huge.film.Mean(x, y).r, atCap.film.Mean(x, y).r);
      EXPECT_EQ(huge.film.Alpha(x, y), atCap.film.Alpha(x, y));
    }
  // And the work stays bounded: a handful of lookups per path, not 1e30.
  EXPECT_LT(huge.counters.densityLookups, 1000u * huge.counters.paths);
}

TEST(UserNumbers, HugeDensityOverAVaryingTransferFunctionFinishes) {
  // A ramp of values under a density of 1e30: the majorant of a cell is the
  // cap while most of its points are far below it, the case where null
  // collisions would explode without the clamp.
  Scene scene =
      test::MakeMediumScene(test::MakeVolume(16, 16, 16, [](int i, int, int) { return i / 15.f; }), 1e30f, RGB(0.8f));
  const SceneView view = scene.Build();
  EXPECT_FALSE(scene.ExtinctionWarning().empty());
  Film film(16, 16);
  TraceCounters counters;
  CpuRenderer(2).Render(view, film, 4, &counters);
  EXPECT_TRUE(AllFinite(film));
  EXPECT_EQ(counters.majorantViolations, 0u);
  EXPECT_LT(counters.densityLookups, 2000u * counters.paths);
}

TEST(UserNumbers, ZeroDensityIsAnEmptyVolume) {
  const Rendered r = RenderConstantMedium(0.f);
  EXPECT_TRUE(r.warning.empty());
  EXPECT_EQ(r.majorant, 0.f);
  EXPECT_EQ(r.counters.realCollisions, 0u);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) EXPECT_EQ(r.film.Alpha(x, y), 0.f);
  EXPECT_TRUE(AllFinite(r.film));
}

TEST(UserNumbers, FineVoxelsRaiseTheCap) {
  // The cap is an optical depth per voxel: 0.1 mm voxels allow 10x the extinction.
  Scene scene = test::MakeMediumScene(test::MakeVolume(
                                          8, 8, 8, [](int, int, int) { return 1.f; }, 0.1f),
                                      100.f, RGB(0.5f));
  scene.Build();
  EXPECT_FLOAT_EQ(scene.MaxExtinction(), kMaxOpticalDepthPerVoxel / 0.1f);
  EXPECT_TRUE(scene.ExtinctionWarning().empty()) << scene.ExtinctionWarning();
}

TEST(UserNumbers, NonFiniteGeometryIsAnError) {
  HostVolume v = test::MakeConstantVolume(4, 1.f);
  v.indexToWorld.m[1][3] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(v.Validate(), InputError);
  HostVolume s = test::MakeConstantVolume(4, 1.f);
  s.indexToWorld.m[0][0] = 0.f;  // a zero spacing
  EXPECT_THROW(s.Validate(), InputError);
  HostVolume n = test::MakeConstantVolume(4, 1.f);
  reinterpret_cast<float*>(n.voxels.MutableData())[5] = std::nanf("");
  try {
    n.Validate();
    ADD_FAILURE() << "a NaN voxel was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite voxel value"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mmrtm
