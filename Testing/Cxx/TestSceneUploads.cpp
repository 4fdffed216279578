// What the CUDA backend sends to the device after each kind of edit
// (SceneUploadPlanner, host code: counted here without a device). For each
// kind, a scene is built and planned, edited, built and planned again; the
// parts asked for must be exactly those the edit changed: a camera move or
// an exposure change nothing (the camera and settings go with each launch),
// a colour the tables only, a density TF point the tables and the majorants
// (then refitted on the device), edited voxels everything that depends on
// them. It catches an upload missed (the device would trace stale tables
// or voxels: the CPU and GPU images would differ) and an upload repeated
// (an unchanged render would copy the scene again).
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "TestSceneHelpers.h"
#include "scene_uploads.h"

namespace mmrtm {
namespace {

// A density TF and an albedo TF over a ramp, a second material picked by a
// range TF, a directional light placed relative to the camera, the default
// sky, the octree.
Scene EditableScene() {
  Scene s = test::MakeMediumScene(test::MakeVolume(24, 20, 16, [](int i, int j, int k) { return (float)(i + j + k); }),
                                  0.2f, {0.8f, 0.8f, 0.8f});
  TransferFunctionDesc albedo = test::IdentityCCTF(0.f, 60.f);
  albedo.channels = 3;
  albedo.values = {1.f, 0.5f, 0.2f, 0.2f, 0.5f, 1.f};
  s.tfs.push_back(albedo);
  s.materials[0].bindings.push_back({1, Quantity::Albedo});
  MaterialDesc bright = s.materials[0];
  bright.name = "bright";
  bright.base[0] = 0.5f;
  s.materials.push_back(bright);
  TransferFunctionDesc pick;
  pick.where = "pick";
  pick.type = TFType::MPCTF;
  pick.keys = {40.f, 60.f};
  pick.materials = {1};
  s.tfs.push_back(pick);
  s.selectors = {2};
  Light sun;
  sun.type = LightType::Directional;
  sun.vector = {0.f, -1.f, 0.f};
  sun.L = {1.f, 1.f, 1.f};
  s.lights.push_back(sun);
  s.environment = EnvironmentMap::DefaultSky();
  return s;
}

struct Expected {
  bool voxels, summaries, majorants, tables, environment;
};

struct Kind {
  std::string name;
  std::function<void(Scene&)> edit;
  Expected uploads;
};

std::string Describe(const SceneUploads& u) {
  return std::string("voxels ") + (u.voxels ? "1" : "0") + ", summaries " + (u.summaries ? "1" : "0") + ", majorants " +
         (u.majorants ? "1" : "0") + ", tables " + (u.tables ? "1" : "0") + ", environment " +
         (u.environment ? "1" : "0");
}

TEST(SceneUploads, EachKindOfEditSendsWhatItChangedAndNothingElse) {
  const std::vector<Kind> kinds = {
      {"unchanged", [](Scene&) {}, {false, false, false, false, false}},
      {"camera", [](Scene& s) { s.camera.azimuth += 30.f; }, {false, false, false, false, false}},
      {"window size",
       [](Scene& s) {
         s.render.width = 40;
         s.render.height = 30;
       },
       {false, false, false, false, false}},
      {"exposure", [](Scene& s) { s.render.exposure = 2.f; }, {false, false, false, false, false}},
      {"sampling setting", [](Scene& s) { s.render.integrator.maxBounces = 3; }, {false, false, false, false, false}},
      {"density TF point", [](Scene& s) { s.tfs[0].values[1] = 30.f; }, {false, false, true, true, false}},
      {"colour TF point", [](Scene& s) { s.tfs[1].values[0] = 0.3f; }, {false, false, false, true, false}},
      {"material colour", [](Scene& s) { s.materials[1].base[1] = 0.1f; }, {false, false, false, true, false}},
      {"material density", [](Scene& s) { s.materials[1].base[0] = 2.f; }, {false, false, true, true, false}},
      {"label range toggled off", [](Scene& s) { s.selectors.clear(); }, {false, false, true, true, false}},
      {"light",
       [](Scene& s) {
         s.lights[0].L = {2.f, 2.f, 2.f};
       },
       {false, false, false, true, false}},
      {"environment",
       [](Scene& s) {
         s.environment = EnvironmentMap::Constant({0.5f, 0.5f, 0.5f});
       },
       {false, false, false, false, true}},
      {"voxels edited in place",
       [](Scene& s) {
         reinterpret_cast<float*>(s.proxies[0].voxels.MutableData())[100] = 59.f;
         s.MarkDataModified();
       },
       {true, true, true, false, false}},
      {"voxels of a region edited",
       [](Scene& s) {
         reinterpret_cast<float*>(s.proxies[0].voxels.MutableData())[100] = 59.f;
         s.MarkRegionModified({4, 4, 0}, {4, 4, 0});
       },
       {true, true, true, false, false}},
      {"new voxel buffer",
       [](Scene& s) {
         HostVolume copy = s.proxies[0];
         s.proxies[0] = std::move(copy);
         s.MarkDataModified();
       },
       {true, true, true, false, false}},
      {"accelerator off",
       [](Scene& s) { s.render.accelerator.kind = MajorantKind::Global; },
       {false, false, true, false, false}},
  };
  for (const Kind& kind : kinds) {
    SCOPED_TRACE(kind.name);
    Scene scene = EditableScene();
    SceneUploadPlanner planner;
    const SceneUploads first = planner.Plan(scene, scene.Build());
    EXPECT_TRUE(first.voxels && first.summaries && first.majorants && first.tables && first.environment)
        << "the first upload sends everything: " << Describe(first);
    kind.edit(scene);
    const SceneUploads after = planner.Plan(scene, scene.Build());
    const Expected& e = kind.uploads;
    EXPECT_EQ(after.voxels, e.voxels) << Describe(after);
    EXPECT_EQ(after.summaries, e.summaries) << Describe(after);
    EXPECT_EQ(after.majorants, e.majorants) << Describe(after);
    EXPECT_EQ(after.tables, e.tables) << Describe(after);
    EXPECT_EQ(after.environment, e.environment) << Describe(after);
    const SceneUploads again = planner.Plan(scene, scene.Build());
    EXPECT_FALSE(again.voxels || again.summaries || again.majorants || again.tables || again.environment)
        << "an unchanged render after the edit uploads nothing: " << Describe(again);
    const SceneUploadCounts& n = planner.Counts();
    EXPECT_EQ(n.tables, 1 + (int)e.tables);
    EXPECT_EQ(n.voxels, 1 + (int)e.voxels);
  }
}

// A light placed relative to the camera turns with it: a camera move then
// sends the tables (the light's direction), and only them.
TEST(SceneUploads, ACameraMoveSendsTheTablesWhenALightIsPlacedByTheCamera) {
  Scene scene = EditableScene();
  scene.cameraLights = {{0, 30.f, 20.f}};
  SceneUploadPlanner planner;
  planner.Plan(scene, scene.Build());
  scene.camera.azimuth += 30.f;
  const SceneUploads u = planner.Plan(scene, scene.Build());
  EXPECT_TRUE(u.tables) << Describe(u);
  EXPECT_FALSE(u.voxels || u.summaries || u.majorants || u.environment) << Describe(u);
}

// A new Scene object over the same voxels (a description parsed again: the
// viewer, the command line) takes the old one's summaries, and with them
// its stamps: the device keeps its voxels. One that does not adopt them
// has new stamps: everything goes up, though the addresses are the same.
TEST(SceneUploads, ANewSceneOverTheSameVoxelsKeepsTheDeviceVoxelsOnlyWhenItAdoptsTheSummaries) {
  Scene first = EditableScene();
  SceneUploadPlanner planner;
  planner.Plan(first, first.Build());

  Scene adopting = EditableScene();
  adopting.proxies = std::move(first.proxies);
  ASSERT_TRUE(adopting.AdoptDataSummariesFrom(first));
  adopting.tfs[0].values[1] = 30.f;
  const SceneUploads u = planner.Plan(adopting, adopting.Build());
  EXPECT_FALSE(u.voxels) << Describe(u);
  EXPECT_FALSE(u.summaries) << Describe(u);
  EXPECT_TRUE(u.majorants && u.tables) << Describe(u);

  Scene fresh = EditableScene();
  fresh.proxies = std::move(adopting.proxies);
  const SceneUploads v = planner.Plan(fresh, fresh.Build());
  EXPECT_TRUE(v.voxels && v.summaries && v.majorants) << Describe(v);
}

// After a failed upload the copy is unknown: everything goes up again.
TEST(SceneUploads, ForgettingAsksForEverything) {
  Scene scene = EditableScene();
  SceneUploadPlanner planner;
  planner.Plan(scene, scene.Build());
  planner.Forget();
  const SceneUploads u = planner.Plan(scene, scene.Build());
  EXPECT_TRUE(u.voxels && u.summaries && u.majorants && u.tables && u.environment) << Describe(u);
}

}  // namespace
}  // namespace mmrtm
