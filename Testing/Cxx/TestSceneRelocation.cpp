// RelocateSceneView moves every array a SceneView points to (the CUDA
// backend's upload). Here the copies are host memory: after relocating, the
// originals are poisoned, and the image rendered from the copies must be the
// same to the last bit. A pointer the relocation forgot would read poison.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "cpu_renderer.h"
#include "mmrtmVolumeLoader.h"
#include "scene_json.h"
#include "scene_relocation.h"

namespace mmrtm {
namespace {

Scene RichScene() {
  // Labels (MDPTF), a range material TF (MPCTF), CCTFs, the default sky's
  // importance-sampling tables, a directional and a point light, the octree.
  nlohmann::json doc = ReadJsonFile(std::string(MMRTM_DATA_DIR) + "/presets/ct-angio-labels.json");
  doc["material_tfs"].push_back({{"type", "mpctf"}, {"proxy", "scalars"}, {"ranges", {{1200, 4000, "vertebra"}}}});
  doc["lights"].push_back({{"type", "point"}, {"position", {0, -300, 0}}, {"intensity", 2e4}});
  doc["render"] = {{"width", 40}, {"height", 32}, {"spp", 4}, {"seed", 5u}};
  SceneInputs inputs;
  inputs.volumes["scalars"] = LoadVolume(std::string(MMRTM_SHARED_DATA_DIR) + "/cta_chest_aorta.nii.gz");
  inputs.volumes["labels"] = LoadVolume(std::string(MMRTM_SHARED_DATA_DIR) + "/cta_chest_aorta_labels.nii.gz", "labels",
                                        Interpolation::Nearest);
  return SceneFromJson(doc, std::move(inputs));
}

RGBImage Render(const SceneView& view, int width, int height) {
  Film film(width, height);
  CpuRenderer(2).Render(view, film, 4);
  return film.Linear();
}

TEST(SceneRelocation, RenderingFromCopiesMatchesAfterTheOriginalsArePoisoned) {
  Scene scene = RichScene();
  const SceneView original = scene.Build();
  ASSERT_EQ(original.majorants.kind, MajorantKind::Octree);
  ASSERT_GT(original.environment.width, 0);
  const RGBImage before = Render(original, scene.render.width, scene.render.height);

  std::vector<std::unique_ptr<uint8_t[]>> copies;
  size_t uploaded = 0;
  const SceneView relocated = RelocateSceneView(original, [&](const void* host, size_t bytes, SceneArrayKind) {
    copies.emplace_back(new uint8_t[bytes]);
    std::memcpy(copies.back().get(), host, bytes);
    uploaded += bytes;
    return static_cast<const void*>(copies.back().get());
  });
  EXPECT_EQ(uploaded, MeasureSceneView(original).Total());
  EXPECT_NE(relocated.classifier.proxies[0].data, original.classifier.proxies[0].data);

  // Poison every original array, and the two arrays of structures (the TF
  // views and the environment's rows) that the relocation rewrites.
  RelocateSceneView(original, [](const void* host, size_t bytes, SceneArrayKind) {
    std::memset(const_cast<void*>(host), 0xA5, bytes);
    return host;
  });
  std::memset(const_cast<TransferFunctionView*>(original.classifier.tfs), 0xA5,
              sizeof(TransferFunctionView) * original.classifier.tfCount);
  std::memset(const_cast<Distribution1DView*>(original.environment.distribution.conditional), 0xA5,
              sizeof(Distribution1DView) * original.environment.distribution.nv);

  const RGBImage after = Render(relocated, scene.render.width, scene.render.height);
  ASSERT_EQ(after.pixels.size(), before.pixels.size());
  double sum = 0;
  for (size_t i = 0; i < before.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(after.pixels[i][c], before.pixels[i][c]) << "pixel " << i;
      sum += before.pixels[i][c];
    }
  EXPECT_GT(sum, 0.0) << "a black image proves nothing";
}

TEST(SceneRelocation, FootprintCountsEveryKind) {
  Scene scene = RichScene();
  const SceneFootprint f = MeasureSceneView(scene.Build());
  EXPECT_EQ(f.voxels, scene.proxies[0].voxels.size() + scene.proxies[1].voxels.size());
  EXPECT_EQ(f.majorants, (size_t)scene.Grid()->NodeCount() * sizeof(float));
  EXPECT_EQ(f.minorants, (size_t)scene.Grid()->NodeCount());  // a byte each
  EXPECT_GT(f.tables, 0u);
  EXPECT_GT(f.environment, 0u);
}

}  // namespace
}  // namespace mmrtm
