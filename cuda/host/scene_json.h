// The JSON scene format (Documentation/scene-format.md): parsing into a
// Scene, and the merging of presets. Host-only.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "scene.h"

namespace mmrtm {

// Loads the volume file `path` as the proxy `name`; supplied by the
// application (the readers live outside cuda/).
using VolumeLoader = std::function<HostVolume(const std::string& path, const std::string& name, Interpolation)>;

// Returns the document with blocks of its own replaced by what they stand
// for; `volume` gives a volume read from the document or the inputs by
// proxy name (null when there is none), `baseDirectory` is the inputs'.
using VolumeByName = std::function<const HostVolume*(const std::string& name)>;
using DocumentExpansion = std::function<nlohmann::json(nlohmann::json doc, const VolumeByName& volume,
                                                       const std::string& baseDirectory)>;

struct SceneInputs {
  VolumeLoader loadVolume;
  // Volumes given outside the scene file (the command line's INPUT and
  // --labels), by proxy name; they take the place of the scene's own files.
  std::map<std::string, HostVolume> volumes;
  // Folder that relative file names in the document are relative to.
  std::string baseDirectory = ".";
  // A front end's expansion of the document's label classes
  // ("label_materials", "label_table"), called once the volumes are read:
  // the labels library's (Labels/label_materials.h,
  // ExpandLabelMaterialsOnLoad). Without it a document with those blocks
  // is an error.
  DocumentExpansion expandDocument;
};

// Reads a JSON document from a file; throws InputError naming the file and
// the line of a syntax error.
nlohmann::json ReadJsonFile(const std::string& path);

// Parses JSON text (comments allowed); throws InputError starting with
// `where` on a syntax error, a number out of range or nesting deeper than
// kMaxJsonDepth. The depth is checked first: the parser copes with any
// depth, but copying or printing the document recurses once per level, and
// a few million levels (a few MB of brackets) overflow the stack.
nlohmann::json ParseJson(const std::string& text, const std::string& where);
constexpr int kMaxJsonDepth = 100;  // scenes nest 6 deep

// Builds a scene from a document. Every problem (unknown key, missing proxy,
// TF without points, wrong type) throws InputError with the JSON path, e.g.
// "materials.bone.tfs.density[0]: a transfer function needs at least one point".
Scene SceneFromJson(const nlohmann::json& doc, SceneInputs inputs);

// Path of preset `name` in the presets folder (Data/presets/NAME.json);
// throws InputError listing the presets there if it does not exist.
std::string PresetPath(const std::string& presetDirectory, const std::string& name);

// The scene file's names of the next-event estimation modes ("one", "all",
// "resampled"); nullopt for another name.
std::optional<LightSampling> ParseLightSampling(const std::string& name);
const char* LightSamplingName(LightSampling mode);

// The scene file's names of the pixel samplers ("sobol", "independent");
// nullopt for another name.
std::optional<PixelSampler> ParsePixelSampler(const std::string& name);
const char* PixelSamplerName(PixelSampler sampler);

}  // namespace mmrtm
