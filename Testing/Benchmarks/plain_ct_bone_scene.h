// The scene two benchmarks measure the plain scene's path on: a volume
// with the ct-bone preset at size x size pixels, meant to be plain (one
// proxy, material and density TF: the caller checks), the path they time.
#pragma once

#include <string>

#include "mmrtmVolumeLoader.h"
#include "scene_json.h"

// `accelerator`: the scene format's render.accelerator.
inline mmrtm::Scene PlainCtBoneScene(const std::string& volume, int size, const std::string& accelerator = "octree") {
  mmrtm::SceneInputs inputs;
  inputs.volumes["scalars"] = mmrtm::LoadVolume(volume, "scalars");
  nlohmann::json doc = mmrtm::ReadJsonFile(std::string(MMRTM_DATA_DIR) + "/presets/ct-bone.json");
  doc["render"]["width"] = size;
  doc["render"]["height"] = size;
  doc["render"]["accelerator"] = accelerator;
  return mmrtm::SceneFromJson(doc, std::move(inputs));
}
