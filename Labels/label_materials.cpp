// See label_materials.h.
#include "label_materials.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>

namespace mmrtm {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& where, const std::string& problem) {
  throw InputError(where + ": " + problem);
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return (char)std::tolower(c); });
  return s;
}

template <typename T>
void CollectIds(const T* v, int64_t n, std::set<int>& ids, const HostVolume& labels) {
  for (int64_t i = 0; i < n; ++i) {
    const float f = (float)v[i];
    if (f == 0.f) continue;
    if (f != std::floor(f) || std::fabs(f) > 1e7f)
      throw InputError(labels.source + ": label maps hold integer ids, found " + std::to_string(f));
    ids.insert((int)f);
  }
}

struct LabelClass {
  std::vector<std::string> match;  // lower case
  std::vector<int> ids;            // exact label ids
  json material;
  bool colorFromTable = true;
};

std::vector<LabelClass> ParseClasses(const json& block) {
  if (!block.contains("classes") || !block["classes"].is_array() || block["classes"].empty())
    Fail("label_materials.classes", "expected a list of classes");
  std::vector<LabelClass> classes;
  for (size_t i = 0; i < block["classes"].size(); ++i) {
    const std::string where = "label_materials.classes[" + std::to_string(i) + "]";
    const json& c = block["classes"][i];
    if (!c.is_object()) Fail(where, "expected an object");
    for (auto it = c.begin(); it != c.end(); ++it)
      if (it.key() != "match" && it.key() != "ids" && it.key() != "material" && it.key() != "color")
        Fail(where, "unknown key '" + it.key() + "' (known: match, ids, material, color)");
    LabelClass lc;
    if (!c.contains("match") && !c.contains("ids"))
      Fail(where, "expected \"match\" (name fragments) or \"ids\" (label ids)");
    if (c.contains("match")) {
      if (!c["match"].is_array() || c["match"].empty())
        Fail(where + ".match", "expected a list of name fragments (\"*\" matches every label)");
      for (const json& m : c["match"]) {
        if (!m.is_string() || m.get<std::string>().empty()) Fail(where + ".match", "expected non-empty strings");
        lc.match.push_back(Lower(m.get<std::string>()));
      }
    }
    if (c.contains("ids")) {
      if (!c["ids"].is_array() || c["ids"].empty()) Fail(where + ".ids", "expected a list of label ids");
      for (const json& id : c["ids"]) {
        if (!id.is_number_integer()) Fail(where + ".ids", "expected integer label ids");
        lc.ids.push_back(id.get<int>());
      }
    }
    lc.material = c.value("material", json::object());
    if (!lc.material.is_object()) Fail(where + ".material", "expected a material object");
    if (lc.material.contains("tfs")) Fail(where + ".material.tfs", "label materials take constant coefficients");
    const std::string color = c.value("color", std::string("table"));
    if (color != "table" && color != "material") Fail(where + ".color", "expected \"table\" or \"material\"");
    lc.colorFromTable = color == "table";
    classes.push_back(std::move(lc));
  }
  return classes;
}

const LabelClass* MatchClass(const std::vector<LabelClass>& classes, int id, const std::string& name) {
  const std::string lower = Lower(name);
  for (const LabelClass& c : classes) {
    if (std::find(c.ids.begin(), c.ids.end(), id) != c.ids.end()) return &c;
    for (const std::string& m : c.match)
      if (m == "*" || lower.find(m) != std::string::npos) return &c;
  }
  return nullptr;
}

}  // namespace

std::vector<int> LabelIdsPresent(const HostVolume& labels) {
  std::set<int> ids;
  const int64_t n = labels.VoxelCount();
  const void* p = labels.voxels.data();
  switch (labels.type) {
    case VoxelType::UInt8:
      CollectIds(static_cast<const uint8_t*>(p), n, ids, labels);
      break;
    case VoxelType::Int16:
      CollectIds(static_cast<const int16_t*>(p), n, ids, labels);
      break;
    case VoxelType::UInt16:
      CollectIds(static_cast<const uint16_t*>(p), n, ids, labels);
      break;
    case VoxelType::Float32:
      CollectIds(static_cast<const float*>(p), n, ids, labels);
      break;
  }
  return {ids.begin(), ids.end()};
}

json ExpandLabelMaterials(json doc, const std::vector<int>& ids, const LabelTable* table) {
  if (!doc.contains("label_materials")) return doc;
  const json block = doc["label_materials"];
  doc.erase("label_materials");
  if (!block.is_object()) Fail("label_materials", "expected an object");
  for (auto it = block.begin(); it != block.end(); ++it)
    if (it.key() != "proxy" && it.key() != "classes")
      Fail("label_materials", "unknown key '" + it.key() + "' (known: proxy, classes)");
  const std::string proxy = block.value("proxy", std::string("labels"));
  const std::vector<LabelClass> classes = ParseClasses(block);

  if (!doc.contains("materials")) doc["materials"] = json::object();
  json points = json::array();
  for (int id : ids) {
    const LabelEntry* entry = table ? table->Find(id) : nullptr;
    std::string name = entry ? entry->name : "label_" + std::to_string(id);
    const LabelClass* c = MatchClass(classes, id, name);
    if (!c) continue;
    while (doc["materials"].contains(name)) name += "_" + std::to_string(id);  // keep the scene's own materials
    json material = c->material;
    if (c->colorFromTable || !material.contains("albedo")) {
      const RGB color = entry ? entry->color : DefaultLabelColor(id);
      material["albedo"] = {color[0], color[1], color[2]};
    }
    doc["materials"][name] = material;
    points.push_back({id, name});
  }
  if (points.empty()) return doc;  // no label matched: nothing to select
  json selectors = json::array({{{"type", "mdptf"}, {"proxy", proxy}, {"points", points}}});
  if (doc.contains("material_tfs")) {
    if (!doc["material_tfs"].is_array()) Fail("material_tfs", "expected a list, highest priority first");
    for (const json& tf : doc["material_tfs"]) selectors.push_back(tf);
  }
  doc["material_tfs"] = selectors;
  return doc;
}

json LabelMaterial(const LabelLook& look) {
  const std::string where = "label material";
  if (!(look.opacity >= 0.0 && look.opacity <= 1.0))
    Fail(where + ".opacity", "expected a number in [0, 1], got " + std::to_string(look.opacity));
  for (double c : look.color)
    if (!(c >= 0.0 && c <= 1.0)) Fail(where + ".color", "expected three numbers in [0, 1]");
  if (!look.surface.is_object()) Fail(where, "the surface parameters must be a JSON object");
  json m = json::object();
  m["density"] = look.visible ? kLabelDensityAtFullOpacity * look.opacity : 0.0;
  m["albedo"] = json::array({look.color[0], look.color[1], look.color[2]});
  static const std::set<std::string> known = {"roughness", "metallic", "surface_probability", "anisotropy", "emission"};
  for (const auto& [key, value] : look.surface.items()) {
    if (!known.count(key))
      Fail(where, "unknown key '" + key + "' (roughness, metallic, surface_probability, anisotropy, emission)");
    m[key] = value;
  }
  return m;
}

void ExpandLabelMaterialsOnLoad(SceneInputs& inputs, std::optional<LabelTable> table) {
  inputs.expandDocument = [table = std::move(table)](json doc, const VolumeByName& volume,
                                                     const std::string& baseDirectory) {
    std::optional<LabelTable> names = table;
    if (doc.contains("label_table")) {
      if (!doc["label_table"].is_string()) Fail("label_table", "expected a file name");
      const fs::path file = doc["label_table"].get<std::string>();
      if (!names) names = ReadLabelTable((file.is_absolute() ? file : fs::path(baseDirectory) / file).string());
      doc.erase("label_table");
    }
    if (!doc.contains("label_materials")) return doc;
    const json& block = doc["label_materials"];
    const std::string proxy = block.is_object() ? block.value("proxy", std::string("labels")) : "labels";
    const HostVolume* labels = volume(proxy);
    if (!labels)
      Fail("label_materials.proxy",
           "needs the label map '" + proxy + "' (give --labels FILE, or a volume of that name)");
    return ExpandLabelMaterials(std::move(doc), LabelIdsPresent(*labels), names ? &*names : nullptr);
  };
}

json WithLabelLooks(json doc, const std::map<int, LabelLook>& looks) {
  if (looks.empty()) return doc;
  if (!doc.contains("label_materials")) doc["label_materials"] = {{"proxy", "labels"}, {"classes", json::array()}};
  json& block = doc["label_materials"];
  if (!block.is_object()) Fail("label_materials", "expected an object");
  json classes = json::array();
  for (const auto& [label, look] : looks)
    classes.push_back({{"ids", {label}}, {"color", "material"}, {"material", LabelMaterial(look)}});
  if (block.contains("classes")) {
    if (!block["classes"].is_array()) Fail("label_materials.classes", "expected a list of classes");
    for (const json& c : block["classes"]) classes.push_back(c);
  }
  block["classes"] = classes;
  return doc;
}

std::map<int, LabelLook> LabelLooksOf(const json& doc, const std::vector<int>& ids, const LabelTable* table) {
  std::map<int, LabelLook> looks;
  if (!doc.contains("label_materials")) return looks;
  json labelsOnly = doc;
  labelsOnly.erase("material_tfs");
  const json expanded = ExpandLabelMaterials(labelsOnly, ids, table);
  if (!expanded.contains("material_tfs")) return looks;
  static const char* const kSurface[] = {"roughness", "metallic", "surface_probability", "anisotropy", "emission"};
  for (const json& point : expanded["material_tfs"][0]["points"]) {
    const json& m = expanded["materials"][point[1].get<std::string>()];
    LabelLook look;
    const json albedo = m.value("albedo", json({1.0, 1.0, 1.0}));
    for (int c = 0; c < 3; ++c)
      look.color[c] = std::clamp(albedo.is_array() ? albedo[c].get<double>() : albedo.get<double>(), 0.0, 1.0);
    look.opacity = LabelOpacity(m.value("density", 1.0));
    for (const char* key : kSurface)
      if (m.contains(key)) look.surface[key] = m[key];
    looks[point[0].get<int>()] = look;
  }
  return looks;
}

double LabelOpacity(double density) { return std::clamp(density / kLabelDensityAtFullOpacity, 0.0, 1.0); }

}  // namespace mmrtm
