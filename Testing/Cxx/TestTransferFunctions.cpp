// The five TF types and the merge rules, against hand-computed values.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "TestSceneHelpers.h"

namespace mmrtm {
namespace {

TransferFunctionDesc Coefficient(TFType type, int proxy, int channels, std::vector<float> keys,
                                 std::vector<float> values) {
  TransferFunctionDesc tf;
  tf.where = "test";
  tf.type = type;
  tf.proxy = proxy;
  tf.channels = channels;
  tf.keys = std::move(keys);
  tf.values = std::move(values);
  return tf;
}

TransferFunctionDesc MaterialTF(TFType type, int proxy, std::vector<float> keys, std::vector<int> materials) {
  TransferFunctionDesc tf;
  tf.where = "test";
  tf.type = type;
  tf.proxy = proxy;
  tf.keys = std::move(keys);
  tf.materials = std::move(materials);
  return tf;
}

// A scene whose TFs are the given ones; one default material reading none.
SceneView BuildWith(Scene& s, std::vector<TransferFunctionDesc> tfs) {
  s.proxies.push_back(test::MakeConstantVolume(2, 0.f));
  s.tfs = std::move(tfs);
  if (s.materials.empty()) {
    MaterialDesc m;
    m.name = "m";
    s.materials.push_back(m);
    s.defaultMaterial = 0;
  }
  return s.Build();
}

// A scene with materials "a" (the default) and "b", for material TFs.
Scene SceneWithMaterialsAB() {
  Scene s;
  for (const char* n : {"a", "b"}) {
    MaterialDesc m;
    m.name = n;
    s.materials.push_back(m);
  }
  s.defaultMaterial = 0;
  return s;
}

float Eval1(const TransferFunctionView& tf, float x) {
  float v[3];
  tf.Evaluate(x, v);
  return v[0];
}

TEST(TransferFunction, CCTFInterpolatesLinearlyAndClamps) {
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CCTF, 0, 1, {100, 200, 400}, {0.f, 1.f, 0.5f})});
  const TransferFunctionView& tf = v.classifier.tfs[0];
  EXPECT_FLOAT_EQ(Eval1(tf, -1000), 0.f);  // clamped below
  EXPECT_FLOAT_EQ(Eval1(tf, 150), 0.5f);
  EXPECT_FLOAT_EQ(Eval1(tf, 200), 1.f);
  EXPECT_FLOAT_EQ(Eval1(tf, 300), 0.75f);
  EXPECT_FLOAT_EQ(Eval1(tf, 5000), 0.5f);  // clamped above
}

TEST(TransferFunction, EvenlySpacedCCTFFindsTheSegmentByArithmeticWithTheSameValues) {
  // Tables sampled from VTK's functions have evenly spaced keys: Evaluate
  // then finds the segment without a binary search. It must be the same
  // segment, hence the same value to the bit, everywhere: at the keys,
  // between them, outside, and for keys a little off even (float rounding
  // of the sampled positions).
  std::mt19937 rng(11);
  for (float jitter : {0.f, 0.1f}) {
    std::vector<float> keys(256), values(256);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int i = 0; i < 256; ++i) {
      keys[i] = -1024.f + 17.3f * ((float)i + jitter * u(rng));
      values[i] = 0.5f + 0.5f * u(rng);
    }
    Scene s;
    SceneView v = BuildWith(s, {Coefficient(TFType::CCTF, 0, 1, keys, values)});
    const TransferFunctionView& fast = v.classifier.tfs[0];
    ASSERT_GT(fast.uniformInverseStep, 0.f) << "evenly spaced keys (jitter " << jitter << ")";
    TransferFunctionView search = fast;
    search.uniformInverseStep = 0.f;  // the binary search
    std::uniform_real_distribution<float> x(keys.front() - 100.f, keys.back() + 100.f);
    for (int i = 0; i < 200000; ++i) {
      const float at = i < 256 ? keys[i] : x(rng);
      const float a = Eval1(fast, at), b = Eval1(search, at);
      ASSERT_EQ(0, std::memcmp(&a, &b, sizeof a)) << "x = " << at;
    }
  }
  // Unevenly spaced keys keep the binary search.
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CCTF, 0, 1, {0, 1, 2, 3, 4, 5, 6, 100}, {0, 1, 0, 1, 0, 1, 0, 1})});
  EXPECT_EQ(v.classifier.tfs[0].uniformInverseStep, 0.f);
}

TEST(TransferFunction, CCTFThreeChannels) {
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CCTF, 0, 3, {0, 10}, {1, 0, 0, 0, 1, 0.5f})});
  float c[3];
  v.classifier.tfs[0].Evaluate(2.5f, c);
  EXPECT_FLOAT_EQ(c[0], 0.75f);
  EXPECT_FLOAT_EQ(c[1], 0.25f);
  EXPECT_FLOAT_EQ(c[2], 0.125f);
}

TEST(TransferFunction, CPCTFIsPiecewiseConstantWithZeroOutside) {
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CPCTF, 0, 1, {0, 10, 10, 20}, {0.3f, 0.7f})});
  const TransferFunctionView& tf = v.classifier.tfs[0];
  EXPECT_FLOAT_EQ(Eval1(tf, -0.5f), 0.f);
  EXPECT_FLOAT_EQ(Eval1(tf, 0.f), 0.3f);
  EXPECT_FLOAT_EQ(Eval1(tf, 9.99f), 0.3f);
  EXPECT_FLOAT_EQ(Eval1(tf, 10.f), 0.7f);  // ranges are half open [lo, hi)
  EXPECT_FLOAT_EQ(Eval1(tf, 20.f), 0.f);
}

TEST(TransferFunction, CDPTFMatchesRoundedValues) {
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CDPTF, 0, 1, {1, 3, 117}, {0.2f, 0.4f, 0.9f})});
  const TransferFunctionView& tf = v.classifier.tfs[0];
  ASSERT_NE(tf.denseIndex, nullptr);  // small label span: dense table
  EXPECT_FLOAT_EQ(Eval1(tf, 1.f), 0.2f);
  EXPECT_FLOAT_EQ(Eval1(tf, 2.f), 0.f);
  EXPECT_FLOAT_EQ(Eval1(tf, 3.2f), 0.4f);
  EXPECT_FLOAT_EQ(Eval1(tf, 117.f), 0.9f);
  EXPECT_FLOAT_EQ(Eval1(tf, 118.f), 0.f);
  EXPECT_FLOAT_EQ(Eval1(tf, -5.f), 0.f);
}

TEST(TransferFunction, CDPTFWideKeysUseBinarySearch) {
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CDPTF, 0, 1, {-100000, 0, 200000}, {0.1f, 0.2f, 0.3f})});
  const TransferFunctionView& tf = v.classifier.tfs[0];
  EXPECT_EQ(tf.denseIndex, nullptr);
  EXPECT_FLOAT_EQ(Eval1(tf, -100000.f), 0.1f);
  EXPECT_FLOAT_EQ(Eval1(tf, 0.f), 0.2f);
  EXPECT_FLOAT_EQ(Eval1(tf, 200000.f), 0.3f);
  EXPECT_FLOAT_EQ(Eval1(tf, 1.f), 0.f);
}

TEST(TransferFunction, MaterialTFsPickMaterials) {
  Scene s = SceneWithMaterialsAB();
  SceneView v =
      BuildWith(s, {MaterialTF(TFType::MPCTF, 0, {0, 5, 5, 8}, {1, 0}), MaterialTF(TFType::MDPTF, 0, {2, 7}, {0, 1})});
  const TransferFunctionView& mp = v.classifier.tfs[0];
  const TransferFunctionView& md = v.classifier.tfs[1];
  EXPECT_EQ(mp.EvaluateMaterial(-1.f), kNoMaterial);
  EXPECT_EQ(mp.EvaluateMaterial(4.9f), 1);
  EXPECT_EQ(mp.EvaluateMaterial(5.f), 0);
  EXPECT_EQ(mp.EvaluateMaterial(8.f), kNoMaterial);
  EXPECT_EQ(md.EvaluateMaterial(2.f), 0);
  EXPECT_EQ(md.EvaluateMaterial(7.f), 1);
  EXPECT_EQ(md.EvaluateMaterial(3.f), kNoMaterial);
}

TEST(TransferFunction, MaxOverRangeBoundsPeaksBetweenEndpoints) {
  Scene s;
  // A narrow peak at 105 between sample values 100 and 110 (DESIGN.md rule 4).
  SceneView v = BuildWith(s, {Coefficient(TFType::CCTF, 0, 1, {104, 105, 106}, {0, 1, 0}),
                              Coefficient(TFType::CPCTF, 0, 1, {50, 60}, {0.5f}),
                              Coefficient(TFType::CDPTF, 0, 1, {3, 9}, {0.25f, 0.75f})});
  float m;
  v.classifier.tfs[0].MaxOverRange(100, 110, &m);
  EXPECT_FLOAT_EQ(m, 1.f);
  EXPECT_FLOAT_EQ(std::max(Eval1(v.classifier.tfs[0], 100), Eval1(v.classifier.tfs[0], 110)), 0.f);
  v.classifier.tfs[0].MaxOverRange(0, 50, &m);
  EXPECT_FLOAT_EQ(m, 0.f);
  v.classifier.tfs[1].MaxOverRange(59, 70, &m);
  EXPECT_FLOAT_EQ(m, 0.5f);
  v.classifier.tfs[1].MaxOverRange(60, 70, &m);  // [50, 60) does not reach 60
  EXPECT_FLOAT_EQ(m, 0.f);
  v.classifier.tfs[2].MaxOverRange(4, 8.6f, &m);  // rounds to 4..9: key 9 reachable
  EXPECT_FLOAT_EQ(m, 0.75f);
  v.classifier.tfs[2].MaxOverRange(4, 8.4f, &m);
  EXPECT_FLOAT_EQ(m, 0.f);
}

TEST(TransferFunction, MinOverRangeBoundsEveryValueFromBelow) {
  // The minorants' bound (majorant_refit.h): at most the TF anywhere in
  // [lo, hi], and for a CCTF the minimum itself (a valley between keys).
  Scene s;
  SceneView v = BuildWith(s, {Coefficient(TFType::CCTF, 0, 1, {0, 10, 20, 30}, {1, 0.2f, 0.8f, 0.5f}),
                              Coefficient(TFType::CPCTF, 0, 1, {0, 10, 10, 20, 25, 30}, {0.5f, 0.7f, 0.9f}),
                              Coefficient(TFType::CDPTF, 0, 1, {3, 4, 5, 9}, {0.25f, 0.75f, 0.5f, 1.f})});
  float m;
  v.classifier.tfs[0].MinOverRange(5, 15, &m);
  EXPECT_FLOAT_EQ(m, 0.2f);  // the key at 10, not an endpoint
  v.classifier.tfs[1].MinOverRange(5, 15, &m);
  EXPECT_FLOAT_EQ(m, 0.5f);  // [0, 10) and [10, 20) cover [5, 15]
  v.classifier.tfs[1].MinOverRange(15, 26, &m);
  EXPECT_FLOAT_EQ(m, 0.f);  // the gap [20, 25) is 0
  v.classifier.tfs[2].MinOverRange(2.6f, 5.4f, &m);
  EXPECT_FLOAT_EQ(m, 0.25f);  // rounds to 3..5, all keys
  v.classifier.tfs[2].MinOverRange(2.6f, 6.f, &m);
  EXPECT_FLOAT_EQ(m, 0.f);  // 6 has no key
  // Random intervals against a dense evaluation.
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> x(-5.f, 35.f);
  for (int t = 0; t < 3; ++t) {
    const TransferFunctionView& tf = v.classifier.tfs[t];
    for (int trial = 0; trial < 2000; ++trial) {
      float lo = x(gen), hi = x(gen);
      if (lo > hi) std::swap(lo, hi);
      float bound;
      tf.MinOverRange(lo, hi, &bound);
      float least = Eval1(tf, hi);
      // (Clamped to hi: lo + (hi - lo) can round past it.)
      for (int k = 0; k <= 400; ++k) least = std::min(least, Eval1(tf, std::min(hi, lo + (hi - lo) * k / 400.f)));
      EXPECT_LE(bound, least) << "tf " << t << " over [" << lo << ", " << hi << "]";
      if (t == 0) EXPECT_NEAR(bound, least, 0.02f) << "a CCTF's bound is its minimum";
    }
  }
}

TEST(TransferFunction, CoversRangeSaysWhetherEveryValueHasAnEntry) {
  Scene s = SceneWithMaterialsAB();
  SceneView v = BuildWith(
      s, {MaterialTF(TFType::MPCTF, 0, {0, 5, 5, 8}, {1, 0}), MaterialTF(TFType::MPCTF, 0, {4, 10, 0, 6}, {0, 1}),
          MaterialTF(TFType::MDPTF, 0, {2, 3, 4, 7}, {0, 1, 0, 1}), Coefficient(TFType::CCTF, 0, 1, {0, 1}, {0, 1})});
  const TransferFunctionView &adjacent = v.classifier.tfs[0], &overlapping = v.classifier.tfs[1],
                             &labels = v.classifier.tfs[2], &curve = v.classifier.tfs[3];
  EXPECT_TRUE(adjacent.CoversRange(0.f, 7.9f));
  EXPECT_FALSE(adjacent.CoversRange(0.f, 8.f));  // [5, 8) stops short of 8
  EXPECT_FALSE(adjacent.CoversRange(-1.f, 3.f));
  EXPECT_TRUE(overlapping.CoversRange(0.f, 9.9f));  // ranges listed out of order
  EXPECT_FALSE(overlapping.CoversRange(9.f, 10.f));
  EXPECT_TRUE(labels.CoversRange(1.6f, 4.4f));  // rounds to 2..4
  EXPECT_FALSE(labels.CoversRange(1.6f, 5.f));  // 5 has no entry
  EXPECT_TRUE(labels.CoversRange(7.f, 7.f));
  EXPECT_TRUE(curve.CoversRange(-100.f, 100.f));
}

// Two proxies: "scalars" (value 300 everywhere) and "labels" (1 in the lower
// half of x, 0 elsewhere), for the merge rules.
struct MergeScene {
  Scene scene;
  SceneView view;
  MergeScene(bool withSelector, float labelDensityFactor) {
    scene.proxies.push_back(test::MakeConstantVolume(4, 300.f));
    HostVolume labels = test::MakeVolume(4, 4, 4, [](int i, int, int) { return i < 2 ? 1.f : 0.f; });
    labels.name = "labels";
    labels.interpolation = Interpolation::Nearest;
    scene.proxies.push_back(std::move(labels));
    // tf 0: CCTF density on scalars, 300 HU -> 0.5
    scene.tfs.push_back(Coefficient(TFType::CCTF, 0, 1, {0, 600}, {0, 1}));
    // tf 1: CDPTF density factor on labels: label 1 -> labelDensityFactor, label 0 -> 1
    scene.tfs.push_back(Coefficient(TFType::CDPTF, 1, 1, {0, 1}, {1.f, labelDensityFactor}));
    // tf 2: CCTF albedo on scalars (RGB)
    scene.tfs.push_back(Coefficient(TFType::CCTF, 0, 3, {0, 600}, {0, 0, 0, 1, 0.5f, 0.25f}));
    // tf 3: MDPTF label 1 -> vessel
    scene.tfs.push_back(MaterialTF(TFType::MDPTF, 1, {1}, {1}));
    MaterialDesc tissue;
    tissue.name = "tissue";
    tissue.base[0] = 2.f;
    tissue.bindings = {{0, Quantity::Density}, {1, Quantity::Density}, {2, Quantity::Albedo}};
    MaterialDesc vessel;
    vessel.name = "vessel";
    vessel.base[0] = 10.f;
    vessel.base[1] = 0.9f;
    vessel.base[2] = 0.1f;
    vessel.base[3] = 0.1f;
    vessel.bindings = {{1, Quantity::Density}};
    scene.materials = {tissue, vessel};
    scene.defaultMaterial = 0;
    if (withSelector) scene.selectors = {3};
    view = scene.Build();
  }
};

TEST(MergeRules, CoefficientsMultiplyAcrossProxies) {
  MergeScene m(false, 0.25f);
  const Classifier& c = m.view.classifier;
  // Label 0 region: 2 * 0.5 * 1; label 1 region: 2 * 0.5 * 0.25.
  EXPECT_FLOAT_EQ(c.Classify({3.f, 1.f, 1.f}).sigma_t, 1.f);
  EXPECT_FLOAT_EQ(c.Classify({0.f, 1.f, 1.f}).sigma_t, 0.25f);
  MaterialCoefficients k = c.Coefficients(c.Classify({3.f, 1.f, 1.f}));
  EXPECT_FLOAT_EQ(k.albedo.r, 0.5f);
  EXPECT_FLOAT_EQ(k.albedo.g, 0.25f);
  EXPECT_FLOAT_EQ(k.albedo.b, 0.125f);
}

TEST(MergeRules, LabelMaterialWinsWhereItsDensityIsAboveZero) {
  MergeScene m(true, 0.25f);
  const Classifier& c = m.view.classifier;
  Classification inLabel = c.Classify({0.f, 1.f, 1.f});
  EXPECT_EQ(inLabel.material, 1);
  EXPECT_FLOAT_EQ(inLabel.sigma_t, 10.f * 0.25f);
  EXPECT_FLOAT_EQ(c.Coefficients(inLabel).albedo.r, 0.9f);
  Classification outside = c.Classify({3.f, 1.f, 1.f});
  EXPECT_EQ(outside.material, 0);
  EXPECT_FLOAT_EQ(outside.sigma_t, 1.f);
}

TEST(MergeRules, LabelMaterialWithZeroDensityFallsBackToDefault) {
  MergeScene m(true, 0.f);  // the label's opacity is zero: the CCTF classifies
  const Classification c = m.view.classifier.Classify({0.f, 1.f, 1.f});
  EXPECT_EQ(c.material, 0);
  EXPECT_FLOAT_EQ(c.sigma_t, 0.f);  // tissue also reads the zero label factor
}

TEST(MergeRules, NearestLookupNeverBlendsLabels) {
  MergeScene m(true, 0.25f);
  // Halfway between label 1 (x=1) and label 0 (x=2): nearest gives 0 or 1, never 0.5.
  const float v = m.view.classifier.SampleProxies({1.4f, 1.f, 1.f}).v[1];
  EXPECT_EQ(v, 1.f);
  EXPECT_EQ(m.view.classifier.SampleProxies({1.6f, 1.f, 1.f}).v[1], 0.f);
}

TEST(MergeRules, GlobalMajorantBoundsEveryMaterial) {
  MergeScene m(true, 3.f);
  // tissue: 2 * 0.5 * max(1, 3) = 3 ; vessel: 10 * 3 = 30.
  EXPECT_FLOAT_EQ(m.view.majorants.globalMajorant, 30.f);
}

TEST(SceneValidation, RejectsBadTransferFunctions) {
  auto expectError = [](TransferFunctionDesc tf, const char* what) {
    Scene s;
    EXPECT_THROW(
        {
          try {
            BuildWith(s, {std::move(tf)});
          } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
            throw;
          }
        },
        InputError);
  };
  expectError(Coefficient(TFType::CCTF, 0, 1, {}, {}), "at least one point");
  expectError(Coefficient(TFType::CCTF, 3, 1, {0}, {1}), "unknown proxy");
  expectError(Coefficient(TFType::CCTF, 0, 1, {5, 1}, {1, 1}), "increasing order");
  expectError(Coefficient(TFType::CDPTF, 0, 1, {1.5f}, {1}), "integers");
  expectError(Coefficient(TFType::CPCTF, 0, 1, {3, 3}, {1}), "empty");
  expectError(Coefficient(TFType::CCTF, 0, 1, {0}, {-1}), "non-negative");
}

}  // namespace
}  // namespace mmrtm
