// One material per label of a segmentation (the scene's "label_materials"
// block): organs, vessels and bones of a label map become distinct
// materials, named and coloured from a label table, chosen by an MDPTF over
// the label proxy; and a label as a front end shows it (LabelLook). The
// front ends' label library (JSON transformations before the tracer's scene
// is built), not the tracer's.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host_volume.h"
#include "label_table.h"
#include "scene_json.h"

namespace mmrtm {

// One label as a front end shows it (a segment in Slicer, a row of the
// viewer's label list): its colour, its opacity in [0, 1], whether it is
// shown, and optional surface and phase parameters ("roughness",
// "metallic", "surface_probability", "anisotropy", "emission").
struct LabelLook {
  std::array<double, 3> color{1.0, 1.0, 1.0};
  double opacity = 1.0;
  bool visible = true;
  nlohmann::json surface = nlohmann::json::object();
  bool operator==(const LabelLook& o) const {
    return color == o.color && opacity == o.opacity && visible == o.visible && surface == o.surface;
  }
};

// The extinction, per millimetre, of a label at opacity 1: as opaque as the
// organs of the ct-organs preset. The one density rule for labels.
constexpr double kLabelDensityAtFullOpacity = 2.5;

// The material of a label (an entry of a scene's "materials"): density
// kLabelDensityAtFullOpacity times the opacity (0 when hidden: the label
// holds nothing), albedo its colour, and its surface parameters. Throws
// InputError naming the key for an unknown parameter or an opacity or
// colour outside [0, 1].
nlohmann::json LabelMaterial(const LabelLook& look);

// The opacity whose label material has this density (LabelMaterial's
// inverse), clamped to [0, 1].
double LabelOpacity(double density);

// The distinct non-zero values of a label map, ascending. Throws InputError
// naming the volume for a non-integer value.
std::vector<int> LabelIdsPresent(const HostVolume& labels);

// Replaces doc["label_materials"] by what it stands for:
//
//   "label_materials": {
//     "proxy": "labels",                       // the label map (default "labels")
//     "classes": [                             // first match wins
//       {"match": ["artery", "aorta"],         // substrings of the label name, case-insensitive; "*" matches all
//        "ids": [5, 6],                        // and/or exact label ids
//        "material": {...},                    // a material as in "materials" (without "tfs")
//        "color": "table" | "material"}        // albedo from the label table (default), or the material's own
//     ]
//   }
//
// For every id in `ids` with a matching class, a material named after the
// label (the table's name, else "label_ID") is added to doc["materials"], and
// an MDPTF over the proxy that maps each id to its material is put first in
// doc["material_tfs"] (labels win over the scene's other material TFs).
// Labels without a table entry are named "label_ID" and get DefaultLabelColor.
// Labels that no class matches stay unclaimed (the default material).
// Errors name the JSON path. A document without "label_materials" is
// returned unchanged.
nlohmann::json ExpandLabelMaterials(nlohmann::json doc, const std::vector<int>& ids, const LabelTable* table);

// The scene format's label classes for SceneFromJson: sets
// inputs.expandDocument to ExpandLabelMaterials over the ids present in the
// label map that "label_materials" names (its "proxy", default "labels"),
// with the names and colours of `table` (the command line's --label-table)
// or else of the document's "label_table" file (relative to the inputs'
// base directory). Throws InputError naming "label_materials.proxy" when
// there is no such label map.
void ExpandLabelMaterialsOnLoad(SceneInputs& inputs, std::optional<LabelTable> table = std::nullopt);

// The document with each look a class of its own ({"ids": [label], "color":
// "material", "material": LabelMaterial(look)}), ahead of the document's
// own classes, so that the looks win. A document without "label_materials"
// gets one over the proxy "labels" that claims just these labels. How a
// front end's per-label edits (the mapper's SetLabelMaterial, the viewer's
// label list) become part of a scene description.
nlohmann::json WithLabelLooks(nlohmann::json doc, const std::map<int, LabelLook>& looks);

// What doc's "label_materials" gives each of `ids` (ExpandLabelMaterials'
// choice), as a look: the albedo as its colour, the density as its opacity
// (LabelOpacity), the material's surface parameters. Labels that no class
// claims are left out; so is every label when the document has no
// "label_materials". Errors as ExpandLabelMaterials'.
std::map<int, LabelLook> LabelLooksOf(const nlohmann::json& doc, const std::vector<int>& ids, const LabelTable* table);

}  // namespace mmrtm
