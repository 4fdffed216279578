// One material per label of a segmentation (the scene's "label_materials"
// block): organs, vessels and bones of a label map become distinct
// materials, named and coloured from a label table, chosen by an MDPTF over
// the label proxy. Host-only set-up code (a JSON transformation).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host_volume.h"
#include "label_table.h"

namespace mmrtm {

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

}  // namespace mmrtm
