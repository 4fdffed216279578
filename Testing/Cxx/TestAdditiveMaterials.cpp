// The additive merge (Classifier::additive, VTK's independent components):
// every material is present at once; sigma_t is the sum of the materials'
// extinctions, the albedo their extinction-weighted mean, and the majorants
// bound the sum (no majorant violation while tracing).
#include <gtest/gtest.h>

#include "TestSceneHelpers.h"
#include "cpu_renderer.h"
#include "scene_json.h"

namespace mmrtm {
namespace {

// Two proxies on one grid: a ramp along x and one along y; material 0 reads
// the first (red), material 1 the second (blue), both with density = value.
Scene TwoComponentScene() {
  Scene scene = test::MakeMediumScene(test::MakeVolume(16, 16, 16, [](int i, int, int) { return i / 15.f; }), 1.f,
                                      RGB(1.f, 0.f, 0.f));
  scene.proxies.push_back(test::MakeVolume(
      16, 16, 16, [](int, int j, int) { return j / 15.f; }, 1.f, "second"));
  TransferFunctionDesc tf = test::IdentityCCTF(0.f, 1.f, 1);
  scene.tfs.push_back(tf);
  MaterialDesc blue = scene.materials[0];
  blue.name = "blue";
  blue.base[1] = 0.f;
  blue.base[3] = 1.f;
  blue.bindings = {{(int)scene.tfs.size() - 1, Quantity::Density}};
  scene.materials.push_back(blue);
  scene.additiveMaterials = true;
  return scene;
}

TEST(AdditiveMaterials, ExtinctionsAddAndAlbedoIsTheWeightedMean) {
  Scene scene = TwoComponentScene();
  const SceneView view = scene.Build();
  const Vec3 p = scene.proxies[0].indexToWorld.ApplyPoint({12.f, 3.f, 8.f});  // x = 12/15, y = 3/15
  const Classification c = view.classifier.Classify(p);
  EXPECT_NEAR(c.sigma_t, 12.f / 15 + 3.f / 15, 1e-5f);
  const MaterialCoefficients k = view.classifier.Coefficients(c);
  EXPECT_NEAR(k.albedo.r, 12.f / 15, 1e-5f);  // red's share: (12/15) / (15/15)
  EXPECT_NEAR(k.albedo.b, 3.f / 15, 1e-5f);
  EXPECT_GE(view.majorants.globalMajorant, 2.f - 1e-5f) << "the global bound is the sum of the maxima";
}

TEST(AdditiveMaterials, MajorantsBoundTheSum) {
  Scene scene = TwoComponentScene();
  for (MajorantKind kind : {MajorantKind::Global, MajorantKind::Macrocell, MajorantKind::Octree}) {
    scene.render.accelerator.kind = kind;
    const SceneView view = scene.Build();
    Film film(24, 24);
    TraceCounters counters;
    CpuRenderer(2).Render(view, film, 8, &counters);
    EXPECT_GT(counters.realCollisions, 0u);
    EXPECT_EQ(counters.majorantViolations, 0u) << "kind " << (int)kind;
  }
}

TEST(AdditiveMaterials, SceneFormatKey) {
  auto parse = [](const nlohmann::json& extra) {
    nlohmann::json doc = {{"materials", {{"a", {{"density", 1.0}}}, {"b", {{"density", 2.0}}}}}};
    doc.merge_patch(extra);
    SceneInputs inputs;
    inputs.volumes["scalars"] = test::MakeConstantVolume(4, 1.f);
    return SceneFromJson(doc, std::move(inputs));
  };
  EXPECT_TRUE(parse({{"additive_materials", true}}).additiveMaterials);
  EXPECT_FALSE(parse({{"default_material", "a"}}).additiveMaterials);
  try {
    parse({{"additive_materials", 1}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("additive_materials: expected true or false"), std::string::npos) << e.what();
  }
  // Both materials everywhere: sigma_t = 1 + 2.
  Scene scene = parse({{"additive_materials", true}});
  const SceneView view = scene.Build();
  EXPECT_FLOAT_EQ(view.classifier.Classify(scene.proxies[0].WorldCenter()).sigma_t, 3.f);
}

}  // namespace
}  // namespace mmrtm
