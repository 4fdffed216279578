#include "label_table.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace mmrtm {

namespace {

// Whole-token integer parse; false for anything else ("12a", "1.5", "").
bool ParseInt(const std::string& s, long long* out) {
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data() + (!s.empty() && s[0] == '+' ? 1 : 0), end, *out);
  return ec == std::errc() && ptr == end;
}

// Whole-token number parse (integer or decimal).
bool ParseNumber(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(*out);
}

}  // namespace

const LabelEntry* LabelTable::Find(int id) const {
  for (const LabelEntry& e : entries)
    if (e.id == id) return &e;
  return nullptr;
}

LabelTable ReadLabelTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the label table");
  LabelTable table;
  table.source = path;
  std::map<int, int> firstLine;  // id -> line, for duplicate messages
  std::string line;
  for (int lineNo = 1; std::getline(in, line); ++lineNo) {
    const std::string where = path + ":" + std::to_string(lineNo) + ": ";
    std::istringstream tokens(line);
    std::vector<std::string> t;
    for (std::string s; tokens >> s;) t.push_back(s);
    if (t.empty() || t[0][0] == '#') continue;

    long long id = 0;
    if (!ParseInt(t[0], &id)) throw InputError(where + "expected an integer label id, got '" + t[0] + "'");
    if (id < 0) throw InputError(where + "label id " + t[0] + " is negative");
    if (id > 2147483647LL) throw InputError(where + "label id " + t[0] + " is too large");
    if (t.size() < 2) throw InputError(where + "label " + t[0] + " has no name");
    auto [it, fresh] = firstLine.emplace((int)id, lineNo);
    if (!fresh)
      throw InputError(where + "duplicate label id " + t[0] + " (first on line " + std::to_string(it->second) + ")");

    LabelEntry e;
    e.id = (int)id;
    e.name = t[1];
    // A colour is exactly 3 or 4 numbers after the name; then they must be
    // valid 0-255 integers (a 0-1 float colour would silently turn black).
    double c[4] = {0, 0, 0, 255};
    const size_t extra = t.size() - 2;
    bool numeric = extra == 3 || extra == 4;
    for (size_t k = 0; numeric && k < extra; ++k) numeric = ParseNumber(t[2 + k], &c[k]);
    if (numeric) {
      for (size_t k = 0; k < extra; ++k)
        if (c[k] != std::floor(c[k]) || c[k] < 0 || c[k] > 255)
          throw InputError(where + "colour value '" + t[2 + k] + "' of label " + t[0] + " is not an integer in 0-255");
      e.color = RGB((float)(c[0] / 255), (float)(c[1] / 255), (float)(c[2] / 255));
      e.opacity = (float)(c[3] / 255);
      e.hasColor = true;
    } else {
      e.color = DefaultLabelColor(e.id);
    }
    table.entries.push_back(std::move(e));
  }
  return table;
}

RGB DefaultLabelColor(int id) {
  if (id == 0) return RGB(0.f);
  // Golden-ratio hue steps keep consecutive ids far apart on the colour
  // wheel; saturation and value cycle with a different period so that ids
  // whose hues come close again still differ.
  const double h = std::fmod(0.11 + id * 0.6180339887498949, 1.0) * 6.0;
  const float s = 0.45f + 0.15f * (float)(id % 3);
  const float v = 0.95f - 0.12f * (float)((id / 3) % 3);
  const int sector = (int)h;
  const float f = (float)(h - sector);
  const float p = v * (1 - s), q = v * (1 - s * f), r = v * (1 - s * (1 - f));
  switch (sector) {
    case 0:
      return RGB(v, r, p);
    case 1:
      return RGB(q, v, p);
    case 2:
      return RGB(p, v, r);
    case 3:
      return RGB(p, q, v);
    case 4:
      return RGB(r, p, v);
    default:
      return RGB(v, p, q);
  }
}

}  // namespace mmrtm
