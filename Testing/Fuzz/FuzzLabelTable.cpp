// libFuzzer target: label tables (cuda/host/label_table.cpp), plain text
// and Slicer's .ctbl, which share one parser: "id name [r g b [a]]" lines.
//
// Findings: anything but a table or an InputError; a table with a negative
// or repeated id, an empty name, or a colour outside 0..1.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string>

#include "FuzzScratch.h"
#include "label_table.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mmrtm::fuzz::WriteScratchFile("labels.ctbl", data, size);
  try {
    const mmrtm::LabelTable table = mmrtm::ReadLabelTable(path);
    std::set<int> ids;
    for (const mmrtm::LabelEntry& e : table.entries) {
      if (e.id < 0 || !ids.insert(e.id).second || e.name.empty()) std::abort();
      for (int c = 0; c < 3; ++c)
        if (!(e.color[c] >= 0 && e.color[c] <= 1)) std::abort();
      if (!(e.opacity >= 0 && e.opacity <= 1)) std::abort();
    }
    mmrtm::fuzz::Outcome("a table of " + std::to_string(table.entries.size()) + " label(s)");
  } catch (const mmrtm::InputError& e) {
    mmrtm::fuzz::Outcome(e.what());
  }
  return 0;
}
