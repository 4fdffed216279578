// Label tables: the names and colours of the labels in a label map, read
// from a plain text file (one label per line, as in 3D Slicer colour tables).
// Host-only set-up code.
#pragma once

#include <string>
#include <vector>

#include "host_volume.h"

namespace mmrtm {

struct LabelEntry {
  int id = 0;
  std::string name;
  RGB color;              // 0-1 display colour; DefaultLabelColor(id) when the file gives none
  float opacity = 1.f;    // 0-1; 1 when the file gives none
  bool hasColor = false;  // whether the file gave the colour
};

struct LabelTable {
  std::string source;                    // the file, for messages
  std::vector<LabelEntry> entries;       // in file order; ids are unique
  const LabelEntry* Find(int id) const;  // null if absent
};

// Reads `id name [r g b [a]]` lines; blank lines and lines starting with '#'
// are ignored. r g b a are integers 0-255 (3D Slicer .ctbl / .txt colour
// tables), converted to 0-1. The tokens after the name are a colour only when
// they are exactly 3 or 4 numbers; anything else there (an atlas code such as
// AAL's `1 Precentral_L 2001`, a remark) is ignored. Throws InputError
// "path:line: problem" for a missing file, an id that is not a non-negative
// integer, a duplicate id, an id without a name, or a colour value that is
// not an integer in 0-255.
LabelTable ReadLabelTable(const std::string& path);

// A colour for a label the table gives none: deterministic, well separated
// for neighbouring ids, moderately saturated. Label 0 (background) is black.
RGB DefaultLabelColor(int id);

}  // namespace mmrtm
