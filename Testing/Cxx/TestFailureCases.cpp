// Failure cases (Documentation/accuracy.md, "Where methods fail"): each test
// shows the failure of a baseline where there is one, and that the default
// (delta and ratio tracking on the conservative octree) survives it.
// Tolerances are test::ExpectUnbiased's (ExpectAgreement.h: 4.5 standard
// errors of each estimator, from its own variance; it prints each check's
// power); the fixed seeds make every run identical.
// A volume of one voxel and a 1 x 1 x 1000 volume are refused with a clear
// message: test_mmrtm_render_cli.py (test_degenerate_volumes).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "ExpectAgreement.h"
#include "FailureCaseScenes.h"
#include "cpu_renderer.h"
#include "film.h"

namespace mmrtm {
namespace {

using failure::Estimate;
using failure::Measure;  // 100000 trials unless told
using failure::Method;

// --- A narrow TF peak -------------------------------------------------------

TEST(NarrowTFPeak, DeltaAndRatioTrackingOnTheOctreeAreExact) {
  for (Method m : {Method::DeltaTracking, Method::RatioTracking}) {
    failure::Case c = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::CellRanges);
    Estimate e = Measure(c, m);
    test::ExpectUnbiased(e.mean, e.standardError, c.exact, "narrow peak, method " + std::to_string((int)m));
    EXPECT_EQ(e.violations, 0u);
  }
}

TEST(NarrowTFPeak, RayMarchingStepsOverIt) {
  // The peak is 0.2 mm wide, the step 1 mm: most marches miss it and those
  // that hit it count a whole step of it, so the transmittance is too high
  // (Jensen: E[exp(-X)] > exp(-E[X]) for the jittered sum X).
  failure::Case c = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::CellRanges, 1.f);
  Estimate e = Measure(c, Method::RayMarching);
  EXPECT_GT(e.mean - c.exact, 0.1) << "ray marching " << e.mean << " vs exact " << c.exact;
  // A step well below the peak's width resolves it.
  failure::Case fine = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::CellRanges, 0.01f);
  Estimate ef = Measure(fine, Method::RayMarching, 5000);  // 2000 lookups a ray
  EXPECT_NEAR(ef.mean, fine.exact, 0.02);
}

TEST(NarrowTFPeak, VoxelMaxMajorantSkipsIt) {
  // No voxel value lies in the peak, so the paper's voxel-value refit gives
  // every node a zero majorant: tracking sees an empty volume (T = 1).
  failure::Case c = failure::NarrowPeak(0.1f, 8.f, MajorantKind::Octree, SummaryMode::VoxelValues);
  Estimate e = Measure(c, Method::DeltaTracking);
  EXPECT_GT(e.mean - c.exact, 0.3) << "voxel-max " << e.mean << " vs exact " << c.exact;
}

// --- A sparse dense structure in a large empty volume -------------------------

TEST(SparseDenseStructure, GlobalMajorantIsSlowAndTheOctreeIsNot) {
  failure::Case global = failure::SparseBlock(128, 1.f, MajorantKind::Global);
  failure::Case octree = failure::SparseBlock(128, 1.f, MajorantKind::Octree);
  Estimate g = Measure(global, Method::RatioTracking), o = Measure(octree, Method::RatioTracking);
  // Both are exact...
  test::ExpectUnbiased(g.mean, g.standardError, global.exact, "sparse block, global majorant");
  test::ExpectUnbiased(o.mean, o.standardError, octree.exact, "sparse block, octree");
  // ...but the global majorant (1 / mm) steps through the whole 128 mm.
  EXPECT_GT(g.lookupsPerRay, 50.0);  // fewer than 128: roulette ends some rays after the block
  EXPECT_LT(o.lookupsPerRay, g.lookupsPerRay / 10.0);
  std::printf("lookups per ray: global %.1f, octree %.1f\n", g.lookupsPerRay, o.lookupsPerRay);
}

// --- Very dense media --------------------------------------------------------

TEST(VeryDenseMedia, TheBounceLimitBoundsRealCollisions) {
  // Albedo 1: Russian roulette never fires (the throughput stays 1), so only
  // the bounce limit ends a path in a medium it cannot leave.
  failure::PathCost dense = failure::DensePathCost(1e4f, RGB(1.f), 8);
  EXPECT_EQ(dense.maxRealPerPath, 9u) << "bounce limit 8: at most 8 scatterings and the collision that ends it";
  // Albedo 0.5: Russian roulette ends most paths well before the limit.
  failure::PathCost absorbing = failure::DensePathCost(1e4f, RGB(0.5f), 32);
  EXPECT_LE(absorbing.maxRealPerPath, 33u);
  EXPECT_LT(absorbing.realPerPath, 4.0);
}

TEST(VeryDenseMedia, LookupsGrowNoFasterThanTheDensity) {
  // Null collisions are not bounded by the bounce limit: in a leaf that is
  // part empty, part dense, tracking takes ~majorant x empty length steps.
  // They must stay bounded by that (linear in the density), not explode.
  failure::PathCost d2 = failure::DensePathCost(1e2f, RGB(0.8f), 32), d4 = failure::DensePathCost(1e4f, RGB(0.8f), 32);
  std::printf("lookups per path: density 1e2 %.1f, 1e4 %.1f; real collisions per path %.2f, %.2f\n", d2.lookupsPerPath,
              d4.lookupsPerPath, d2.realPerPath, d4.realPerPath);
  EXPECT_LT(d4.lookupsPerPath, 100.0 * 1.1 * d2.lookupsPerPath);
  EXPECT_LT(d4.realPerPath, 4.0);
}

// --- Grazing rays along slices ----------------------------------------------

TEST(GrazingRays, AlongASliceOnANodeFace) {
  // z = 16 is a voxel slice and a face between nodes at every level.
  for (MajorantKind kind : {MajorantKind::Macrocell, MajorantKind::Octree}) {
    for (float z : {16.f, 16.f + 1e-5f, 16.f - 1e-5f, 16.5f, 15.f}) {
      failure::Case c = failure::SliceSheet(z, 0.05f, kind);
      for (Method m : {Method::DeltaTracking, Method::RatioTracking}) {
        Estimate e = Measure(c, m);
        test::ExpectUnbiased(e.mean, e.standardError, c.exact,
                             "sheet at z " + std::to_string(z) + ", kind " + std::to_string((int)kind) + ", method " +
                                 std::to_string((int)m),
                             1e-6);
        EXPECT_EQ(e.violations, 0u);
      }
    }
  }
}

TEST(GrazingRays, TippedAcrossTheSheet) {
  for (float tilt : {1e-4f, 1e-2f}) {
    failure::Case c = failure::SliceSheet(16.f, 0.05f, MajorantKind::Octree, tilt);
    Estimate e = Measure(c, Method::RatioTracking);
    test::ExpectUnbiased(e.mean, e.standardError, c.exact, "tilt " + std::to_string(tilt), 1e-4);
    EXPECT_EQ(e.violations, 0u);
  }
}

// --- Degenerate TFs ---------------------------------------------------------

Film RenderUnderConstantSky(Scene& scene, TraceCounters* ctr) {
  scene.environment = EnvironmentMap::Constant(RGB(0.3f, 0.4f, 0.5f));
  scene.render.width = scene.render.height = 24;
  SceneView view = scene.Build();
  Film film(24, 24);
  CpuRenderer(2).Render(view, film, 4, ctr);
  return film;
}

TEST(DegenerateTF, AllZeroShowsTheEnvironmentWithoutALookup) {
  failure::Case c = failure::AllZeroTF(MajorantKind::Octree);
  TraceCounters ctr;
  Film film = RenderUnderConstantSky(c.scene, &ctr);
  EXPECT_EQ(ctr.densityLookups, 0u) << "an empty grid needs no lookup";
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      RGB p = film.Mean(x, y);
      EXPECT_FLOAT_EQ(p.r, 0.3f);
      EXPECT_FLOAT_EQ(p.b, 0.5f);
    }
}

TEST(DegenerateTF, AllOneIsAHomogeneousBox) {
  // A constant TF of 1 over noisy data: Beer-Lambert through the box.
  for (MajorantKind kind : {MajorantKind::Global, MajorantKind::Octree}) {
    failure::Case c = failure::AllOneTF(kind);
    for (Method m : {Method::DeltaTracking, Method::RatioTracking}) {
      Estimate e = Measure(c, m);
      test::ExpectUnbiased(e.mean, e.standardError, c.exact, "all-one TF, kind " + std::to_string((int)kind));
      if (kind == MajorantKind::Octree && m == Method::RatioTracking)
        EXPECT_LT(e.lookupsPerRay, 0.1 * 16.0 * 1.5 + 1.0) << "a tight majorant: about sigma x length lookups";
    }
  }
}

TEST(DegenerateTF, StepAtTheDataMaximum) {
  for (MajorantKind kind : {MajorantKind::Global, MajorantKind::Macrocell, MajorantKind::Octree}) {
    failure::Case c = failure::SaturatedBlock(0.4f, kind);
    for (Method m : {Method::DeltaTracking, Method::RatioTracking}) {
      Estimate e = Measure(c, m);
      test::ExpectUnbiased(e.mean, e.standardError, c.exact, "step at the maximum, kind " + std::to_string((int)kind),
                           1e-3);
      EXPECT_EQ(e.violations, 0u);
    }
  }
}

}  // namespace
}  // namespace mmrtm
