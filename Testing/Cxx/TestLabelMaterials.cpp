// Tests of the "label_materials" expansion: one material per label, named
// and coloured from a label table, selected by an MDPTF that takes priority.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "label_materials.h"
#include "TestOutputFolder.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace mmrtm {
namespace {

json Classes() {
  return json::parse(R"({
    "label_materials": {
      "classes": [
        {"match": ["artery", "aorta"], "color": "material", "material": {"density": 4, "albedo": [0.9, 0.1, 0.1]}},
        {"match": ["vertebra"], "material": {"density": 3}},
        {"match": ["*"], "material": {"density": 2}}
      ]
    },
    "materials": {"tissue": {"density": 1}},
    "material_tfs": [{"type": "mpctf", "proxy": "scalars", "ranges": [[100, 200, "tissue"]]}]
  })");
}

LabelTable Table() {
  const std::string path = (TestOutputFolder() / "label_table.txt").string();
  std::ofstream(path) << "# test\n1 aorta\n2 vertebrae_T12 255 0 0\n3 liver 0 255 0 255\n";
  return ReadLabelTable(path);
}

TEST(LabelMaterials, OneMaterialPerLabelFirstMatchingClassWins) {
  const LabelTable table = Table();
  const json doc = ExpandLabelMaterials(Classes(), {1, 2, 3, 9}, &table);
  EXPECT_FALSE(doc.contains("label_materials"));
  const json& m = doc["materials"];
  ASSERT_EQ(m.size(), 5u);  // tissue + 4 labels
  EXPECT_EQ(m["aorta"]["density"], 4);
  EXPECT_EQ(m["aorta"]["albedo"], json({0.9, 0.1, 0.1}));  // the class's own colour
  EXPECT_EQ(m["vertebrae_T12"]["density"], 3);
  EXPECT_EQ(m["vertebrae_T12"]["albedo"], json({1.0, 0.0, 0.0}));  // the table's colour
  EXPECT_EQ(m["liver"]["density"], 2);
  const RGB palette = DefaultLabelColor(9);
  EXPECT_FLOAT_EQ(m["label_9"]["albedo"][1].get<float>(), palette[1]);  // not in the table
  // The labels' MDPTF comes first, then the scene's own material TFs.
  ASSERT_EQ(doc["material_tfs"].size(), 2u);
  EXPECT_EQ(doc["material_tfs"][0]["type"], "mdptf");
  EXPECT_EQ(doc["material_tfs"][0]["proxy"], "labels");
  EXPECT_EQ(doc["material_tfs"][0]["points"], json({{1, "aorta"}, {2, "vertebrae_T12"}, {3, "liver"}, {9, "label_9"}}));
  EXPECT_EQ(doc["material_tfs"][1]["type"], "mpctf");
}

TEST(LabelMaterials, AClassByIdWinsOverTheNamesAfterIt) {
  // The viewer edits one label as a class of its own, put first.
  json doc = Classes();
  doc["label_materials"]["classes"].insert(doc["label_materials"]["classes"].begin(),
                                           json::parse(R"({"ids": [3], "color": "material",
                                             "material": {"density": 0.5, "albedo": [0, 0, 1], "roughness": 0.2}})"));
  const LabelTable table = Table();
  const json expanded = ExpandLabelMaterials(doc, {1, 2, 3}, &table);
  EXPECT_EQ(expanded["materials"]["liver"]["density"], 0.5);
  EXPECT_EQ(expanded["materials"]["liver"]["albedo"], json({0, 0, 1}));
  EXPECT_EQ(expanded["materials"]["aorta"]["density"], 4);  // the others as before
  json bad = Classes();
  bad["label_materials"]["classes"][0] = json::parse(R"({"ids": [1.5], "material": {}})");
  try {
    ExpandLabelMaterials(bad, {1}, &table);
    FAIL() << "a fractional id must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("label_materials.classes[0].ids"), std::string::npos) << e.what();
  }
}

TEST(LabelMaterials, UnmatchedLabelsStayUnclaimed) {
  json doc = Classes();
  doc["label_materials"]["classes"].erase(2);  // no "*"
  const LabelTable table = Table();
  const json out = ExpandLabelMaterials(doc, {1, 3}, &table);
  EXPECT_TRUE(out["materials"].contains("aorta"));
  EXPECT_FALSE(out["materials"].contains("liver"));
  EXPECT_EQ(out["material_tfs"][0]["points"].size(), 1u);
}

TEST(LabelMaterials, NameClashWithASceneMaterialKeepsBoth) {
  json doc = Classes();
  doc["materials"]["liver"] = {{"density", 7}};
  const LabelTable table = Table();
  const json out = ExpandLabelMaterials(doc, {3}, &table);
  EXPECT_EQ(out["materials"]["liver"]["density"], 7);
  EXPECT_EQ(out["materials"]["liver_3"]["density"], 2);
}

TEST(LabelMaterials, ErrorsNameThePath) {
  json doc = Classes();
  doc["label_materials"]["classes"][0]["colour"] = "table";
  try {
    ExpandLabelMaterials(doc, {1}, nullptr);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("label_materials.classes[0]: unknown key 'colour'"), std::string::npos)
        << e.what();
  }
  doc = Classes();
  doc["label_materials"]["classes"][1]["match"] = json::array();
  EXPECT_THROW(ExpandLabelMaterials(doc, {1}, nullptr), InputError);
}

TEST(LabelMaterials, IdsPresentInAVolume) {
  HostVolume v;
  v.name = "labels";
  v.source = "test";
  v.dims = {4, 1, 1};
  v.type = VoxelType::UInt16;
  const uint16_t values[4] = {0, 300, 7, 300};
  v.voxels.assign(reinterpret_cast<const uint8_t*>(values), reinterpret_cast<const uint8_t*>(values) + 8);
  EXPECT_EQ(LabelIdsPresent(v), (std::vector<int>{7, 300}));
  v.type = VoxelType::Float32;
  const float fractional[2] = {1.5f, 2.f};
  v.dims = {2, 1, 1};
  v.voxels.assign(reinterpret_cast<const uint8_t*>(fractional), reinterpret_cast<const uint8_t*>(fractional) + 8);
  EXPECT_THROW(LabelIdsPresent(v), InputError);
}

// The scene format's label classes reach the tracer's parser through the
// labels library: with ExpandLabelMaterialsOnLoad a document's classes and
// table name the materials of the labels present; without it the parser
// refuses them by name (rather than rendering without the labels); a
// --label-table takes the place of the document's table; a missing label
// map is named. Catches the expansion lost on the way to SceneFromJson.
TEST(LabelMaterials, TheSceneParserExpandsLabelClassesThroughTheLabelsLibrary) {
  auto volume = [](const std::string& name, std::vector<uint16_t> values) {
    HostVolume v;
    v.name = name;
    v.source = name;
    v.dims = {int(values.size()), 1, 1};
    v.type = VoxelType::UInt16;
    v.voxels.assign(reinterpret_cast<const uint8_t*>(values.data()),
                    reinterpret_cast<const uint8_t*>(values.data() + values.size()));
    return v;
  };
  const LabelTable table = Table();
  json doc = json::parse(R"({"materials": {"tissue": {"density": 1}},
    "label_materials": {"classes": [{"match": ["*"], "material": {"density": 2}}]}})");
  doc["label_table"] = table.source;
  auto inputs = [&](bool labels) {
    SceneInputs in;
    in.volumes["scalars"] = volume("scalars", {10, 20, 30, 40});
    if (labels) in.volumes["labels"] = volume("labels", {0, 1, 2, 1});
    return in;
  };
  try {
    SceneFromJson(doc, inputs(true));
    FAIL() << "label classes were parsed without the labels library";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("label_materials"), std::string::npos) << e.what();
  }
  SceneInputs in = inputs(true);
  ExpandLabelMaterialsOnLoad(in);
  const Scene scene = SceneFromJson(doc, std::move(in));
  EXPECT_GE(scene.MaterialIndex("aorta"), 0);
  EXPECT_GE(scene.MaterialIndex("vertebrae_T12"), 0);
  EXPECT_LT(scene.MaterialIndex("liver"), 0);  // not present in the label map
  LabelTable other;
  other.entries.push_back({1, "renamed", DefaultLabelColor(1), 1.f, false});
  in = inputs(true);
  ExpandLabelMaterialsOnLoad(in, other);
  EXPECT_GE(SceneFromJson(doc, std::move(in)).MaterialIndex("renamed"), 0);
  in = inputs(false);
  ExpandLabelMaterialsOnLoad(in);
  try {
    SceneFromJson(doc, std::move(in));
    FAIL() << "label classes without a label map were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("label_materials.proxy"), std::string::npos) << e.what();
  }
}

// The one label rule (Slicer's segments, the viewer's label list): density
// 2.5/mm times the opacity, none when hidden, the colour as albedo, the
// surface parameters kept. Catches another density rule or an opacity that
// does not come back through LabelOpacity.
TEST(LabelMaterials, ALabelsLookIsOneMaterial) {
  LabelLook look;
  look.color = {0.8, 0.2, 0.1};
  look.opacity = 0.4;
  look.surface = {{"roughness", 0.3}, {"surface_probability", 0.75}};
  const json m = LabelMaterial(look);
  EXPECT_DOUBLE_EQ(m["density"].get<double>(), 0.4 * kLabelDensityAtFullOpacity);
  EXPECT_EQ(m["albedo"], json::array({0.8, 0.2, 0.1}));
  EXPECT_EQ(m["roughness"], 0.3);
  EXPECT_EQ(m["surface_probability"], 0.75);
  EXPECT_DOUBLE_EQ(LabelOpacity(m["density"].get<double>()), 0.4);
  EXPECT_DOUBLE_EQ(LabelOpacity(10.0), 1.0);
  look.visible = false;
  EXPECT_EQ(LabelMaterial(look)["density"], 0.0);
  // Through the scene format: the label's material is this one.
  look.visible = true;
  const json doc = {
      {"label_materials",
       {{"classes", json::array({{{"ids", {7}}, {"color", "material"}, {"material", LabelMaterial(look)}}})}}}};
  const json expanded = ExpandLabelMaterials(doc, {7}, nullptr);
  EXPECT_DOUBLE_EQ(expanded["materials"]["label_7"]["density"].get<double>(), 0.4 * kLabelDensityAtFullOpacity);
  EXPECT_EQ(expanded["materials"]["label_7"]["albedo"], json::array({0.8, 0.2, 0.1}));
}

TEST(LabelMaterials, ALabelsLookOutOfRangeIsAnErrorNamingIt) {
  LabelLook look;
  look.opacity = 1.5;
  try {
    LabelMaterial(look);
    FAIL() << "an opacity of 1.5 was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("opacity"), std::string::npos) << e.what();
  }
  look.opacity = 1.0;
  look.surface = {{"shininess", 3}};
  try {
    LabelMaterial(look);
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shininess"), std::string::npos) << e.what();
  }
}

// A front end's edited labels (the mapper's SetLabelMaterial over a
// description, the viewer's saved scene) win over the description's classes,
// and a look read back from the description is the look put in. Catches
// looks put after the classes (the "*" class would win), a document without
// "label_materials" left without the looks, and a look that does not come
// back through LabelLooksOf.
TEST(LabelMaterials, LabelLooksWinOverTheDescriptionsClassesAndReadBack) {
  const LabelTable table = Table();
  LabelLook look;
  look.color = {0.1, 0.2, 0.9};
  look.opacity = 0.5;
  look.surface = {{"roughness", 0.3}};
  const json doc = WithLabelLooks(Classes(), {{3, look}});
  const std::map<int, LabelLook> read = LabelLooksOf(doc, {1, 2, 3, 9}, &table);
  ASSERT_EQ(read.size(), 4u);
  EXPECT_TRUE(read.at(3) == look);
  EXPECT_DOUBLE_EQ(read.at(1).opacity, LabelOpacity(4));                // aorta: its class
  EXPECT_EQ(read.at(2).color, (std::array<double, 3>{1.0, 0.0, 0.0}));  // vertebra: the table's colour
  EXPECT_DOUBLE_EQ(read.at(9).opacity, LabelOpacity(2));                // the "*" class
  // Without classes of its own: the looks alone, other labels unclaimed.
  const json bare = WithLabelLooks(json::object(), {{3, look}});
  EXPECT_EQ(bare["label_materials"]["proxy"], "labels");
  const std::map<int, LabelLook> alone = LabelLooksOf(bare, {1, 3}, nullptr);
  ASSERT_EQ(alone.size(), 1u);
  EXPECT_TRUE(alone.at(3) == look);
  EXPECT_TRUE(LabelLooksOf(json::object(), {1, 3}, nullptr).empty());
  EXPECT_EQ(WithLabelLooks(Classes(), {}), Classes());
}

// The presets and the rule agree: ct-organs' class for any other label is
// a label at opacity 1. Catches a preset or a rule changed alone.
TEST(LabelMaterials, TheOrgansPresetsOtherLabelsAreAtFullOpacity) {
  std::ifstream in(std::string(MMRTM_DATA_DIR) + "/presets/ct-organs.json");
  ASSERT_TRUE(in) << MMRTM_DATA_DIR << "/presets/ct-organs.json";
  const json preset = json::parse(in);
  const json& last = preset["label_materials"]["classes"].back();
  ASSERT_EQ(last["match"], json::array({"*"}));
  EXPECT_DOUBLE_EQ(last["material"]["density"].get<double>(), kLabelDensityAtFullOpacity);
}

}  // namespace
}  // namespace mmrtm
