// The hierarchical majorant grid (paper section 4, DESIGN.md rule 4):
//   - conservative: along random rays through real volumes, under adversarial
//     TFs, no sampled extinction exceeds the majorant the traversal gives
//     there, and where the traversal skips, the extinction is zero; the
//     paper's voxel-value refit violates this under a narrow TF peak;
//   - the minorants (residual ratio tracking's control) are lower bounds:
//     no sampled extinction is below the minorant the traversal gives there,
//     with material TFs that leave gaps, and label maps;
//   - a refit after a TF change (or a data change in a region) equals a full
//     rebuild;
//   - unbiased: images with no accelerator, the macrocell grid and the octree
//     agree within their noise, also after a TF change and refit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

#include "ExpectAgreement.h"
#include "ReplicateRenders.h"
#include "TestSceneHelpers.h"
#include "cpu_renderer.h"
#include "mmrtm/majorant_refit.h"
#include "mmrtm/rng.h"
#include "mmrtmVolumeLoader.h"

namespace mmrtm {
namespace {

std::string Data(const char* name) { return std::string(MMRTM_SHARED_DATA_DIR) + "/" + name; }

TransferFunctionDesc CCTF(std::vector<float> keys, std::vector<float> values, int proxy = 0) {
  TransferFunctionDesc tf;
  tf.where = "test";
  tf.type = TFType::CCTF;
  tf.proxy = proxy;
  tf.keys = std::move(keys);
  tf.values = std::move(values);
  return tf;
}

// A single label's TF: `value` at label `label` of proxy `proxy`, 0 elsewhere.
TransferFunctionDesc SingleLabel(float label, float value, int proxy) {
  TransferFunctionDesc tf;
  tf.where = "test";
  tf.type = TFType::CDPTF;
  tf.proxy = proxy;
  tf.keys = {label};
  tf.values = {value};
  return tf;
}

// One material whose density is `density` times the given TFs.
Scene SceneWith(std::vector<HostVolume> proxies, std::vector<TransferFunctionDesc> densityTFs, float density,
                MajorantKind kind, SummaryMode summary = SummaryMode::CellRanges) {
  Scene s;
  s.proxies = std::move(proxies);
  s.tfs = std::move(densityTFs);
  MaterialDesc m;
  m.name = "m";
  m.base[0] = density;
  for (int i = 0; i < (int)s.tfs.size(); ++i) m.bindings.push_back({i, Quantity::Density});
  s.materials.push_back(m);
  s.defaultMaterial = 0;
  s.render.accelerator.kind = kind;
  s.render.accelerator.grid.summary = summary;
  return s;
}

struct Violations {
  int64_t lookups = 0, overMajorant = 0, inSkippedSpace = 0, segments = 0;
  int64_t underMinorant = 0, segmentsWithMinorant = 0;
};

// Random rays through the volume: every point sampled in a segment must have
// sigma_min <= sigma_t * scale <= sigma_maj of the segment; every point the
// traversal skips must have sigma_t == 0.
Violations CheckAlongRandomRays(const SceneView& s, int rays, float scale, uint64_t seed) {
  Violations v;
  PCG32 rng(seed, 1);
  const VolumeView& v0 = s.classifier.proxies[0];
  const Affine3 indexToWorld = AffineInverse(v0.worldToIndex);
  const Vec3 hi{(float)(v0.nx - 1), (float)(v0.ny - 1), (float)(v0.nz - 1)};
  const Vec3 center = indexToWorld.ApplyPoint(hi * 0.5f);
  const float radius = Length(indexToWorld.ApplyVector(hi));
  for (int r = 0; r < rays; ++r) {
    // From a random point on a sphere around the volume, toward a random
    // point inside it (so that most rays cross it, many obliquely).
    Vec3 from = center + SampleUniformSphere(rng.Uniform(), rng.Uniform()) * radius;
    Vec3 target = indexToWorld.ApplyPoint({rng.Uniform() * hi.x, rng.Uniform() * hi.y, rng.Uniform() * hi.z});
    Ray ray{from, Normalize(target - from)};
    Ray indexRay;
    float t0, t1;
    if (!s.DomainInterval(ray, kInfinity, &indexRay, &t0, &t1)) continue;
    MajorantIterator it = s.majorants.Begin(indexRay, t0, t1, scale);
    RayMajorantSegment seg;
    float covered = t0;
    auto check = [&](float a, float b, float majorant, float minorant, bool skipped) {
      for (int k = 0; k < 8; ++k) {
        const float t = a + (b - a) * ((k + rng.Uniform()) / 8.f);
        // The box test widens [t0, t1] by a few ulps (pbrt's gamma(3)); the
        // grid ends at the volume's faces. Points beyond them are outside.
        const Vec3 p = indexRay(t);
        if (skipped && (p.x < 0.f || p.y < 0.f || p.z < 0.f || p.x > hi.x || p.y > hi.y || p.z > hi.z)) continue;
        // Where the tracker's lookups sample: proxies on proxy 0's grid at
        // the index ray's point (Classifier::onProxy0Grid).
        const float sigma = scale * s.classifier.Classify(ray(t), indexRay(t)).sigma_t;
        ++v.lookups;
        if (skipped && sigma > 0.f) ++v.inSkippedSpace;
        if (!skipped && sigma > majorant * (1.f + 1e-5f)) ++v.overMajorant;
        if (!skipped && sigma < minorant * (1.f - 1e-5f)) ++v.underMinorant;
      }
    };
    while (it.Next(&seg)) {
      ++v.segments;
      if (seg.tMin > covered) check(covered, seg.tMin, 0.f, 0.f, true);
      check(seg.tMin, seg.tMax, seg.sigma_maj, seg.sigma_min, false);
      v.segmentsWithMinorant += seg.sigma_min > 0.f;
      covered = std::max(covered, seg.tMax);
    }
    if (covered < t1) check(covered, t1, 0.f, 0.f, true);
  }
  return v;
}

class Conservative : public ::testing::TestWithParam<MajorantKind> {};

TEST_P(Conservative, NarrowPeakStepAndLabelOnRealVolumes) {
  // Narrow TF peaks between two integer voxel values (no voxel has them):
  // amid soft tissue, and at the air-skin boundary, which interpolation
  // crosses in one cell where neighbouring voxels are hundreds of HU apart;
  // a step; and a peak on a second TF multiplied with a constant one.
  std::vector<std::vector<TransferFunctionDesc>> adversarial = {
      {CCTF({105.f, 105.5f, 106.f}, {0.f, 1.f, 0.f})},
      {CCTF({-500.f, -499.5f, -499.f}, {0.f, 1.f, 0.f})},
      {CCTF({300.f, 300.f}, {0.f, 1.f})},
      {CCTF({-2000.f, 4000.f}, {1.f, 1.f}), CCTF({40.f, 40.5f, 41.f}, {0.f, 1.f, 0.f})},
  };
  HostVolume ct = LoadVolume(Data("ct_head_cranium.nrrd"));
  for (auto& tfs : adversarial) {
    Scene scene = SceneWith({ct}, tfs, 2.f, GetParam());
    SceneView s = scene.Build();
    for (float scale : {1.f, 0.8f}) {
      Violations v = CheckAlongRandomRays(s, 3000, scale, 7);
      EXPECT_GT(v.segments, 1500);
      EXPECT_EQ(v.overMajorant, 0) << "of " << v.lookups << " lookups";
      EXPECT_EQ(v.inSkippedSpace, 0) << "of " << v.lookups << " lookups";
      EXPECT_EQ(v.underMinorant, 0) << "of " << v.lookups << " lookups";
    }
  }
}

// The ct-soft-tissue shape: an MPCTF on CT values picks "skin" on [-450,
// 200) and "bone" on [gapEnd, 4000), each with a CCTF density; no default, so
// that air, and the gap [200, gapEnd) when gapEnd > 200, have no material.
Scene TwoMaterialScene(HostVolume ct, float gapEnd, MajorantKind kind) {
  Scene s;
  s.proxies.push_back(std::move(ct));
  s.tfs.push_back(CCTF({-450.f, -250.f, -50.f, 150.f}, {0.f, 0.5f, 1.f, 1.f}));
  s.tfs.push_back(CCTF({200.f, 400.f, 800.f}, {0.2f, 0.6f, 1.f}));
  TransferFunctionDesc pick;
  pick.where = "test";
  pick.type = TFType::MPCTF;
  pick.keys = {-450.f, 200.f, gapEnd, 4000.f};
  pick.materials = {0, 1};
  s.tfs.push_back(pick);
  s.selectors = {2};
  for (int m = 0; m < 2; ++m) {
    MaterialDesc d;
    d.name = m == 0 ? "skin" : "bone";
    d.base[0] = m == 0 ? 0.15f : 1.5f;
    d.bindings.push_back({m, Quantity::Density});
    s.materials.push_back(d);
  }
  s.render.accelerator.kind = kind;
  return s;
}

TEST_P(Conservative, MinorantsBoundTheExtinctionFromBelow) {
  // Residual ratio tracking is exact in the minorant's part: a minorant above
  // the extinction anywhere would bias every shadow ray through it.
  HostVolume ct = LoadVolume(Data("ct_head_cranium.nrrd"));
  struct Case {
    const char* what;
    Scene scene;
  };
  std::vector<Case> cases;
  cases.push_back({"two materials", TwoMaterialScene(ct, 200.f, GetParam())});
  // A gap without a material inside the bone ramp: leaves whose values span
  // it must get 0, although both materials' densities are above 0 there.
  cases.push_back({"a gap", TwoMaterialScene(ct, 300.f, GetParam())});
  // A constant density: every non-empty node's minorant is its majorant
  // (to a 255th).
  cases.push_back({"constant", SceneWith({ct}, {CCTF({-2000.f, 4000.f}, {1.f, 1.f})}, 0.5f, GetParam())});
  for (Case& c : cases) {
    SceneView s = c.scene.Build();
    // (At a small scale the octree climbs: upper nodes' minorants count.)
    for (float scale : {1.f, 0.8f, 0.02f}) {
      Violations v = CheckAlongRandomRays(s, 2000, scale, 13);
      EXPECT_EQ(v.underMinorant, 0) << c.what << ": of " << v.lookups << " lookups";
      EXPECT_EQ(v.overMajorant, 0) << c.what << ": of " << v.lookups << " lookups";
      EXPECT_GT(v.segmentsWithMinorant, v.segments / 20) << c.what << ": the minorants must not all be 0";
    }
  }
}

TEST_P(Conservative, MinorantsUnderALabelMapAndACurve) {
  // A label's density (nearest lookup, on the labels' own file) times a CT
  // ramp: the minorant is 0 in leaves with other labels and above 0 only
  // where the label and the ramp's upper values fill a leaf.
  HostVolume ct = LoadVolume(Data("cta_chest_aorta.nii.gz"));
  HostVolume labels = LoadVolume(Data("cta_chest_aorta_labels.nii.gz"), "labels", Interpolation::Nearest);
  Scene scene =
      SceneWith({ct, labels}, {SingleLabel(3.f, 1.f, 1), CCTF({-1000.f, 100.f}, {0.5f, 1.f})}, 5.f, GetParam());
  SceneView s = scene.Build();
  Violations v = CheckAlongRandomRays(s, 1500, 1.f, 17);
  EXPECT_EQ(v.underMinorant, 0) << "of " << v.lookups << " lookups";
  EXPECT_GT(v.segmentsWithMinorant, 0) << "the label's interior must have a minorant";
}

TEST_P(Conservative, SingleLabelTimesCTOnTwoProxies) {
  // MDPTF-like density: one label (nearest lookup) times a CT ramp; the labels
  // come on their own file, aligned in world space.
  HostVolume ct = LoadVolume(Data("cta_chest_aorta.nii.gz"));
  HostVolume labels = LoadVolume(Data("cta_chest_aorta_labels.nii.gz"), "labels", Interpolation::Nearest);
  Scene scene = SceneWith({ct, labels}, {SingleLabel(3.f, 1.f, 1), CCTF({100.f, 400.f}, {0.f, 1.f})}, 5.f, GetParam());
  SceneView s = scene.Build();
  Violations v = CheckAlongRandomRays(s, 1500, 1.f, 11);
  EXPECT_EQ(v.overMajorant, 0) << "of " << v.lookups << " lookups";
  EXPECT_EQ(v.inSkippedSpace, 0);
  // Most of the volume holds no label 3: most leaves must be empty, so that
  // the traversal skips them.
  ASSERT_NE(scene.Grid(), nullptr);
  const MajorantGridView& g = scene.Grid()->View();
  const int64_t leaves = scene.Grid()->LeafCount();
  int64_t nonEmpty = 0;
  for (int64_t i = 0; i < leaves; ++i) nonEmpty += g.majorants[g.offset[g.leafLevel] + i] > 0.f;
  EXPECT_GT(nonEmpty, 0);
  EXPECT_LT(nonEmpty, leaves / 20) << nonEmpty << " of " << leaves << " leaves";
}

TEST(LabelSummaries, OnSameVoxelGridToleratesTheRoundingOfFarOrigins) {
  // The MRI's header: an origin of a few hundred mm. Through world-to-index
  // and back, its map rounds by about 1e-5, which the earlier test (the
  // composed map within 1e-5 of the identity) took for another grid.
  HostVolume a;
  a.dims = {4, 5, 6};
  a.indexToWorld = IndexToWorld({-388.26, -81.12, 405.42}, {1.0, 0.898437, 0.898437}, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  HostVolume b = a;
  b.indexToWorld = AffineInverse(a.View().worldToIndex);
  EXPECT_TRUE(OnSameVoxelGrid(b, a));
  EXPECT_TRUE(OnSameVoxelGrid(a, a));
  HostVolume shifted = a;
  shifted.indexToWorld.m[0][3] += 0.05f;  // a twentieth of a voxel
  EXPECT_FALSE(OnSameVoxelGrid(shifted, a));
  HostVolume finer = a;
  finer.indexToWorld.m[1][1] *= 0.999f;
  EXPECT_FALSE(OnSameVoxelGrid(finer, a));
  HostVolume larger = a;
  larger.dims = {4, 5, 7};
  EXPECT_FALSE(OnSameVoxelGrid(larger, a));
}

TEST(LabelSummaries, ALabelMapOnTheImageGridIsSummarizedOverExactVoxelBoxes) {
  // The CTA's label map shares the image's grid: the tracker samples it at
  // the image's index coordinates, and a leaf's summary holds the labels of
  // the voxels of its closed box [x s, (x + 1) s] and no others. So with a
  // density of one label times a constant, the non-empty leaves are exactly
  // those whose box holds that label (a one-voxel margin, which the grid
  // took when the identity test failed on rounding, gave 486 leaves for 212).
  HostVolume ct = LoadVolume(Data("cta_chest_aorta.nii.gz"));
  HostVolume labels = LoadVolume(Data("cta_chest_aorta_labels.nii.gz"), "labels", Interpolation::Nearest);
  ASSERT_TRUE(OnSameVoxelGrid(labels, ct));
  Scene scene = SceneWith({ct, labels}, {SingleLabel(3.f, 1.f, 1), CCTF({-5000.f, 5000.f}, {1.f, 1.f})}, 1.f,
                          MajorantKind::Octree);
  const SceneView s = scene.Build();
  EXPECT_TRUE(s.classifier.onProxy0Grid[1]);
  const MajorantGridView& g = scene.Grid()->View();
  const int L = g.leafLevel, size = g.nodeSize[L];
  std::set<int64_t> expected;
  for (int z = 0; z < labels.dims[2]; ++z)
    for (int y = 0; y < labels.dims[1]; ++y)
      for (int x = 0; x < labels.dims[0]; ++x) {
        if (labels.Value(x + (int64_t)labels.dims[0] * (y + (int64_t)labels.dims[1] * z)) != 3.f) continue;
        // The leaves whose closed box holds voxel (x, y, z): one per axis,
        // two where the voxel lies on a face between leaves.
        const int p[3] = {x, y, z};
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
          hi[a] = std::min(p[a] / size, g.res[L][a] - 1);
          lo[a] = p[a] % size == 0 && p[a] > 0 ? p[a] / size - 1 : hi[a];
        }
        for (int lz = lo[2]; lz <= hi[2]; ++lz)
          for (int ly = lo[1]; ly <= hi[1]; ++ly)
            for (int lx = lo[0]; lx <= hi[0]; ++lx) expected.insert(g.Index(L, lx, ly, lz));
      }
  ASSERT_GT(expected.size(), 10u);
  int64_t nonEmpty = 0, unexpected = 0;
  for (int64_t i = g.offset[L]; i < g.offset[L] + scene.Grid()->LeafCount(); ++i) {
    if (!(g.majorants[i] > 0.f)) continue;
    ++nonEmpty;
    unexpected += !expected.count(i);
  }
  EXPECT_EQ(unexpected, 0);
  EXPECT_EQ(nonEmpty, (int64_t)expected.size());
}

INSTANTIATE_TEST_SUITE_P(Accelerators, Conservative, ::testing::Values(MajorantKind::Macrocell, MajorantKind::Octree),
                         [](const auto& info) { return info.param == MajorantKind::Octree ? "Octree" : "Macrocell"; });

TEST(VoxelMaxRefit, ViolatesConservativenessUnderANarrowPeak) {
  HostVolume ct = LoadVolume(Data("ct_head_cranium.nrrd"));
  // A peak at 30.5 HU, amid the brain's values: no voxel holds it, so the
  // voxel-value refit makes every node empty, while trilinear interpolation
  // crosses it in many cells.
  Scene scene = SceneWith({ct}, {CCTF({30.f, 30.5f, 31.f}, {0.f, 1.f, 0.f})}, 2.f, MajorantKind::Octree,
                          SummaryMode::VoxelValues);
  SceneView s = scene.Build();
  Violations v = CheckAlongRandomRays(s, 1500, 1.f, 7);
  EXPECT_GT(v.inSkippedSpace + v.overMajorant, 10) << "of " << v.lookups << " lookups";
}

TEST(Refit, AfterATransferFunctionChangeEqualsAFullRebuild) {
  HostVolume ct = LoadVolume(Data("ct_head_headsq.nrrd"));
  Scene refitted = SceneWith({ct}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f, MajorantKind::Octree);
  refitted.Build();
  const double buildSeconds = refitted.Grid()->LastBuildSeconds();
  refitted.tfs[0] = CCTF({900.f, 950.f, 1000.f}, {0.f, 0.7f, 0.f});  // the user edits the TF
  refitted.materials[0].base[0] = 3.f;
  refitted.Build();
  EXPECT_EQ(refitted.Grid()->LastBuildSeconds(), buildSeconds) << "a TF change must not rebuild the summaries";

  Scene rebuilt = SceneWith({ct}, {CCTF({900.f, 950.f, 1000.f}, {0.f, 0.7f, 0.f})}, 3.f, MajorantKind::Octree);
  rebuilt.Build();
  const MajorantGridView &a = refitted.Grid()->View(), &b = rebuilt.Grid()->View();
  ASSERT_EQ(refitted.Grid()->NodeCount(), rebuilt.Grid()->NodeCount());
  int nonZero = 0;
  for (int64_t i = 0; i < refitted.Grid()->NodeCount(); ++i) {
    ASSERT_EQ(a.majorants[i], b.majorants[i]) << "node " << i;
    ASSERT_EQ(a.minorants[i], b.minorants[i]) << "node " << i;
    nonZero += a.majorants[i] > 0.f;
  }
  EXPECT_GT(nonZero, 0);
  EXPECT_LT(nonZero, refitted.Grid()->NodeCount()) << "a narrow TF should leave empty nodes";
}

// An unchanged Build, or one after a camera or settings edit, must not
// refit (a refit on every Build cost an unchanged render of the 256 x 256 x
// 108 head CT 2 ms with the octree, 309 ms with octree-voxelmax:
// performance.md); an edit of anything a refit reads must, and give
// the majorants of a scene built afresh, bit for bit. Catches a refit on
// every Build, and a field the refit reads that the scene's comparison
// leaves out (stale majorants: a biased image, as the planted defect
// MapperColorRefit shows one layer up).
TEST(Refit, OnlyWhenWhatARefitReadsChanged) {
  HostVolume ct = LoadVolume(Data("ct_head_headsq.nrrd"));
  Scene scene = SceneWith({ct}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f, MajorantKind::Octree);
  scene.Build();
  EXPECT_TRUE(scene.GridRefittedByLastBuild()) << "the first build";
  scene.Build();
  EXPECT_FALSE(scene.GridRefittedByLastBuild()) << "an unchanged build";
  scene.camera.azimuth = 40.f;
  scene.render.width = 300;
  scene.render.samplesPerPixel = 3;
  scene.render.exposure = 2.f;
  scene.render.integrator.maxBounces = 2;
  scene.Build();
  EXPECT_FALSE(scene.GridRefittedByLastBuild()) << "camera and settings only";

  auto majorants = [](const Scene& s) {
    const MajorantGridView& g = s.Grid()->View();
    return std::vector<float>(g.majorants, g.majorants + s.Grid()->NodeCount());
  };
  const std::pair<const char*, std::function<void(Scene&)>> edits[] = {
      {"a TF value", [](Scene& s) { s.tfs[0].values[1] = 0.5f; }},
      {"a TF key", [](Scene& s) { s.tfs[0].keys[0] = 1000.f; }},
      {"the density", [](Scene& s) { s.materials[0].base[0] = 1e4f; }},  // now clamped by MaxExtinction()
      {"the voxel spacing",
       [](Scene& s) {
         for (auto& row : s.proxies[0].indexToWorld.m)
           for (int a = 0; a < 3; ++a) row[a] *= 2.f;
       }},
  };
  for (const auto& [what, edit] : edits) {
    const std::vector<float> before = majorants(scene);
    edit(scene);
    scene.Build();
    EXPECT_TRUE(scene.GridRefittedByLastBuild()) << what;
    EXPECT_FALSE(scene.GridSummariesBuiltByLastBuild()) << what << ": a refit, not a rebuild";
    Scene fresh = SceneWith({scene.proxies[0]}, {scene.tfs[0]}, scene.materials[0].base[0], MajorantKind::Octree);
    fresh.Build();
    EXPECT_EQ(majorants(scene), majorants(fresh)) << what;
    EXPECT_NE(majorants(scene), before) << what << " should change the majorants (else the check is empty)";
    scene.Build();
    EXPECT_FALSE(scene.GridRefittedByLastBuild()) << "unchanged after " << what;
  }
}

TEST(Refit, ByteTablesGiveTheSameLeafMajorantsAsTheBins) {
  // The CPU refit takes each leaf's maximum (and minimum) through per-byte
  // tables; the CUDA refit walks the set bins. Both must give every leaf
  // the same values.
  HostVolume ct = LoadVolume(Data("ct_head_headsq.nrrd"));
  Scene scene = SceneWith({ct}, {CCTF({300.f, 700.f, 900.f, 1400.f, 2600.f}, {0.f, 0.9f, 0.1f, 1.f, 0.3f})}, 2.f,
                          MajorantKind::Octree);
  SceneView view = scene.Build();
  const MajorantGrid& grid = *scene.Grid();
  const MajorantGrid::RefitTables tables = grid.MakeRefitTables(view.classifier);
  RefitInputs bins, bytes;
  bins.summaries[0] = bytes.summaries[0] = grid.Summaries().Words(0);
  bins.binMax = bytes.binMax = tables.binMax.data();
  bins.binMaterials = bytes.binMaterials = tables.binMaterials.data();
  bins.binMin = bytes.binMin = tables.binMin.data();
  bins.uncoveredBins = bytes.uncoveredBins = tables.uncoveredBins.data();
  bytes.byteMax = tables.byteMax.data();
  bytes.byteMin = tables.byteMin.data();
  int nonZero = 0, nonZeroMinorants = 0;
  for (int64_t s = 0; s < (int64_t)grid.Summaries().Count(); ++s) {
    const float a = SummaryMajorant(view.classifier, bins, s), b = SummaryMajorant(view.classifier, bytes, s);
    ASSERT_EQ(a, b) << "summary " << s;
    nonZero += a > 0.f;
    const float lowerA = SummaryMinorant(view.classifier, bins, s), lowerB = SummaryMinorant(view.classifier, bytes, s);
    ASSERT_EQ(lowerA, lowerB) << "summary " << s;
    nonZeroMinorants += lowerA > 0.f;
  }
  EXPECT_GT(nonZero, 100);
  EXPECT_GT(nonZeroMinorants, 10);
}

// Proxy k's summary words of a leaf.
std::vector<uint64_t> LeafWords(const MajorantGrid& grid, int k, int64_t leaf) {
  const uint64_t* w = grid.Summaries().Words(k) + (size_t)grid.LeafSummaryIds()[(size_t)leaf] * kSummaryWords;
  return {w, w + kSummaryWords};
}

// Every stored summary is held by some leaf, and no two are equal.
void ExpectDistinctAndHeld(const MajorantGrid& grid) {
  const LeafSummaryTable& table = grid.Summaries();
  std::vector<char> held(table.Count(), 0);
  for (uint32_t id : grid.LeafSummaryIds()) {
    ASSERT_LT(id, table.Count());
    held[id] = 1;
  }
  EXPECT_EQ(std::count(held.begin(), held.end(), 1), (long)table.Count()) << "a summary no leaf holds";
  std::set<std::vector<uint64_t>> distinct;
  for (size_t s = 0; s < table.Count(); ++s) {
    std::vector<uint64_t> tuple;
    for (int k = 0; k < table.ProxyCount(); ++k)
      tuple.insert(tuple.end(), table.Words(k) + s * kSummaryWords, table.Words(k) + (s + 1) * kSummaryWords);
    distinct.insert(tuple);
  }
  EXPECT_EQ(distinct.size(), table.Count()) << "a summary stored twice";
}

TEST(LeafSummaries, TheTableGivesEqualTuplesOneIdAndCompactKeepsWhatIsHeld) {
  LeafSummaryTable table;
  table.Reset(2);
  // Tuples of 2 proxies x 4 words; many more than the initial hash slots,
  // so that the table rehashes on the way.
  auto tuple = [](uint64_t i) {
    std::vector<uint64_t> t(2 * kSummaryWords, 0);
    t[i % 8] = 1ull << (i % 61);
    t[(i / 8) % 8] |= 1ull << ((i / 8) % 59);
    t[7] ^= i;
    return t;
  };
  std::vector<uint32_t> ids;
  for (uint64_t i = 0; i < 5000; ++i) ids.push_back(table.Insert(tuple(i).data()));
  ASSERT_EQ(table.Count(), 5000u);
  for (uint64_t i = 0; i < 5000; ++i) ASSERT_EQ(table.Insert(tuple(i).data()), ids[i]) << "tuple " << i;
  ASSERT_EQ(table.Count(), 5000u) << "an equal tuple was stored again";
  // Keep every third: Compact drops the rest and renumbers, words intact.
  std::vector<uint32_t> held;
  for (uint64_t i = 0; i < 5000; i += 3) held.push_back(ids[i]);
  EXPECT_EQ(table.Compact(held), 5000u - held.size());
  ASSERT_EQ(table.Count(), held.size());
  for (size_t j = 0; j < held.size(); ++j) {
    const std::vector<uint64_t> t = tuple(3 * j);
    ASSERT_LT(held[j], table.Count());
    for (int k = 0; k < 2; ++k)
      for (int w = 0; w < kSummaryWords; ++w)
        ASSERT_EQ(table.Words(k)[held[j] * kSummaryWords + w], t[k * kSummaryWords + w]) << "tuple " << 3 * j;
    ASSERT_EQ(table.Insert(t.data()), held[j]) << "the hash index after Compact";
  }
  EXPECT_EQ(table.Insert(tuple(1).data()), held.size()) << "a dropped tuple is new again";
}

TEST(LeafSummaries, LeavesShareTheirSummaries) {
  // The refit's cost and the summaries' memory follow the distinct
  // summaries: on a real CT most leaves share theirs (measured: 10,904 of
  // 365,148 leaves here).
  Scene scene = SceneWith({LoadVolume(Data("ct_head_headsq.nrrd"))}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f,
                          MajorantKind::Octree);
  scene.Build();
  const MajorantGrid& grid = *scene.Grid();
  ASSERT_EQ((int64_t)grid.LeafSummaryIds().size(), grid.LeafCount());
  EXPECT_LT(grid.Summaries().Count() * 10, (size_t)grid.LeafCount());
  EXPECT_GT(grid.Summaries().Count(), 100u) << "leaves of a CT differ";
  ExpectDistinctAndHeld(grid);
  EXPECT_LT(grid.SummaryBytes(), (size_t)grid.LeafCount() * 8) << "4 B of id per leaf, and the table";
}

// The summary build shares the layers of leaves among its threads as they
// come free: the ids, summaries and majorants must not depend on the
// thread count (catches a layer written by two threads, or ids taken in
// the order the threads finish), and the build reports its progress up to 1.
TEST(LeafSummaries, TheBuildIsTheSameOnAnyThreadCountAndReportsItsProgress) {
  const HostVolume ct = LoadVolume(Data("ct_head_cranium.nrrd"));
  Scene one = SceneWith({ct}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f, MajorantKind::Octree);
  one.render.accelerator.grid.threads = 1;
  one.Build();
  Scene three = SceneWith({ct}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f, MajorantKind::Octree);
  three.render.accelerator.grid.threads = 3;
  std::vector<double> fractions;
  three.buildProgress = [&](double f) { fractions.push_back(f); };
  three.Build();
  EXPECT_EQ(one.Grid()->LeafSummaryIds(), three.Grid()->LeafSummaryIds());
  for (int64_t leaf = 0; leaf < one.Grid()->LeafCount(); ++leaf)
    ASSERT_EQ(LeafWords(*one.Grid(), 0, leaf), LeafWords(*three.Grid(), 0, leaf)) << "leaf " << leaf;
  for (int64_t i = 0; i < one.Grid()->NodeCount(); ++i)
    ASSERT_EQ(one.Grid()->View().majorants[i], three.Grid()->View().majorants[i]) << "node " << i;
  ASSERT_GT(fractions.size(), 2u);
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_EQ(fractions.back(), 1.0);
  // A refit reads no voxels: it reports nothing.
  fractions.clear();
  three.tfs[0] = CCTF({600.f, 1500.f}, {0.f, 1.f});
  three.Build();
  EXPECT_TRUE(fractions.empty());
}

// Writes `value` into the voxels [lo, hi] of the scene's 64 x 64 x N int16
// proxy 0 (ct_head_headsq), as an editing tool does before it marks the region.
void PaintBlock(Scene& scene, const std::array<int, 3>& lo, const std::array<int, 3>& hi, int16_t value) {
  int16_t* voxels = reinterpret_cast<int16_t*>(scene.proxies[0].voxels.MutableData());
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) voxels[x + 64 * (y + 64 * z)] = value;
}

TEST(Refit, AfterADataChangeInARegionEqualsAFullRebuild) {
  HostVolume ct = LoadVolume(Data("ct_head_headsq.nrrd"));
  Scene scene = SceneWith({ct}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f, MajorantKind::Octree);
  scene.Build();
  // Paint a bright block into the data, then update only that region.
  const std::array<int, 3> lo{20, 30, 40}, hi{27, 33, 52};
  PaintBlock(scene, lo, hi, 3000);
  const double fullBuildSeconds = scene.Grid()->LastBuildSeconds();
  scene.MarkRegionModified(lo, hi);
  SceneView updated = scene.Build();
  EXPECT_LT(scene.Grid()->LastBuildSeconds(), fullBuildSeconds) << "only the region's leaves are rebuilt";

  Scene rebuilt = SceneWith({scene.proxies[0]}, {CCTF({500.f, 1500.f}, {0.f, 1.f})}, 1.f, MajorantKind::Octree);
  rebuilt.Build();
  for (int64_t i = 0; i < rebuilt.Grid()->NodeCount(); ++i)
    ASSERT_EQ(updated.majorants.grid.majorants[i], rebuilt.Grid()->View().majorants[i]) << "node " << i;
  // The same summary in every leaf, and the edited grid's table holds no
  // summary that only the old data had.
  for (int64_t leaf = 0; leaf < rebuilt.Grid()->LeafCount(); ++leaf)
    ASSERT_EQ(LeafWords(*scene.Grid(), 0, leaf), LeafWords(*rebuilt.Grid(), 0, leaf)) << "leaf " << leaf;
  ExpectDistinctAndHeld(*scene.Grid());
}

TEST(Refit, ARegionEditedBeyondTheValueRangeStillBoundsTheExtinction) {
  // The summaries bin integer voxels through a table of the values the
  // last full build saw; an edit to values beyond them (here above the CT's
  // maximum, 3926) must still be binned, into the top bin.
  HostVolume ct = LoadVolume(Data("ct_head_headsq.nrrd"));
  Scene scene = SceneWith({ct}, {CCTF({500.f, 4500.f, 5000.f}, {0.f, 0.f, 1.f})}, 2.f, MajorantKind::Octree);
  scene.Build();
  const std::array<int, 3> lo{20, 30, 40}, hi{27, 33, 52};
  PaintBlock(scene, lo, hi, 5000);
  scene.MarkRegionModified(lo, hi);
  SceneView updated = scene.Build();
  const MajorantGridView& g = scene.Grid()->View();
  const int L = g.leafLevel, size = g.nodeSize[L];
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) {
        const int64_t leaf = x / size + (int64_t)g.res[L][0] * (y / size + (int64_t)g.res[L][1] * (z / size));
        ASSERT_GE(updated.majorants.grid.majorants[g.offset[L] + leaf], 2.f) << "voxel " << x << " " << y << " " << z;
      }
}

// The image with accelerator `kind`: kReplicates renders of kReplicateSpp
// samples from seeds firstSeed, firstSeed + 1, ... (independently scrambled
// Sobol' nets, whose spread is the error of their mean: ImageAgreement.h).
constexpr int kReplicates = 8, kReplicateSpp = 12;
test::ImageEstimate RenderWith(Scene& scene, MajorantKind kind, uint64_t firstSeed) {
  scene.render.accelerator.kind = kind;
  const SceneView view = scene.Build();
  TraceCounters ctr;
  test::ImageEstimate e = test::RenderReplicates(view, kReplicates, kReplicateSpp, firstSeed, &ctr);
  EXPECT_EQ(ctr.majorantViolations, 0u);
  return e;
}

TEST(Unbiased, AcceleratorsAgreeWithinNoise) {
  Scene scene = SceneWith({LoadVolume(Data("ct_head_headsq.nrrd"))}, {CCTF({600.f, 1400.f}, {0.f, 1.f})}, 0.8f,
                          MajorantKind::Global);
  scene.materials[0].base[6] = 0.5f;  // surface and volume scattering
  scene.environment = EnvironmentMap::DefaultSky();
  scene.camera.zoom = 1.3f;
  scene.render.width = scene.render.height = 48;
  const test::ImageEstimate none = RenderWith(scene, MajorantKind::Global, 100);
  const test::ImageEstimate macrocell = RenderWith(scene, MajorantKind::Macrocell, 200);
  const test::ImageEstimate octree = RenderWith(scene, MajorantKind::Octree, 300);
  // Two unbiased images fail a comparison with probability below 1e-4; a
  // change of a channel's mean over the covered pixels by the comparison's
  // power (printed; asserted at most 2 %) fails with probability 1 - 1e-4
  // (ImageAgreement.h). Shown: the octree's image made 2 % darker fails.
  test::ExpectAgreement("none / macrocell", none, macrocell);
  test::ExpectAgreement("none / octree", none, octree);
  test::ExpectDisagreement("octree 2 % darker / none", test::Scaled(octree, 0.98), none);
  // After a TF change and refit, the octree still agrees with the global majorant...
  scene.tfs[0] = CCTF({1800.f, 2600.f}, {0.f, 1.f});  // only the densest bone remains
  const test::ImageEstimate octreeAfter = RenderWith(scene, MajorantKind::Octree, 400);
  const test::ImageEstimate noneAfter = RenderWith(scene, MajorantKind::Global, 500);
  test::ExpectAgreement("after the refit: none / octree", noneAfter, octreeAfter);
  // ...and the test tells the two TFs apart.
  test::ExpectDisagreement("old TF / new TF", none, octreeAfter);
}

}  // namespace
}  // namespace mmrtm
