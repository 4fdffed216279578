// The five reference scenes of Documentation/accuracy.md, as mmrtm-render
// makes them from Testing/Accuracy/reference_scenes.json (which the accuracy
// scripts read too): the volume and label map from the shared data folder,
// the preset and the scene file over it, at a size of the test's choosing.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mmrtmVolumeLoader.h"
#include "scene_json.h"

namespace mmrtm::test {

inline nlohmann::json ReferenceSceneList() {
  nlohmann::json list = ReadJsonFile(std::string(MMRTM_SOURCE_DIR) + "/Testing/Accuracy/reference_scenes.json");
  list.erase("_comment");
  return list;
}

inline std::vector<std::string> ReferenceSceneNames() {
  std::vector<std::string> names;
  for (const auto& [name, scene] : ReferenceSceneList().items()) names.push_back(name);
  return names;
}

// `name`'s scene at width x height, with unbiased shadows (the accuracy
// scripts' --shadow-scale 1).
inline Scene LoadReferenceScene(const std::string& name, int width, int height) {
  const nlohmann::json entry = ReferenceSceneList().at(name);
  nlohmann::json doc = nlohmann::json::object();
  SceneInputs inputs;
  inputs.baseDirectory = ".";
  if (entry.contains("preset"))
    doc = ReadJsonFile(PresetPath(std::string(MMRTM_DATA_DIR) + "/presets", entry["preset"].get<std::string>()));
  if (entry.contains("scene")) {
    const std::filesystem::path scene = std::filesystem::path(MMRTM_SOURCE_DIR) / entry["scene"].get<std::string>();
    doc.merge_patch(ReadJsonFile(scene.string()));
    inputs.baseDirectory = scene.parent_path().string();
  }
  doc["render"].merge_patch({{"width", width}, {"height", height}, {"shadow_extinction_scale", 1.0}});
  const std::string data = std::string(MMRTM_SHARED_DATA_DIR) + "/";
  inputs.volumes["scalars"] = LoadVolume(data + entry["volume"].get<std::string>(), "scalars");
  if (entry.contains("labels"))
    inputs.volumes["labels"] = LoadVolume(data + entry["labels"].get<std::string>(), "labels", Interpolation::Nearest);
  return SceneFromJson(doc, std::move(inputs));
}

}  // namespace mmrtm::test
