// Tests of ReadLabelTable on the label tables in MMRTM_SHARED_DATA_DIR and on
// small hand-made files (3D Slicer colour tables, non-colour extras, every
// error) written to the test's own output folder.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "label_table.h"
#include "TestOutputFolder.h"

namespace fs = std::filesystem;
using namespace mmrtm;

namespace {

std::string Write(const std::string& name, const std::string& text) {
  const fs::path p = TestOutputFolder() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// The message of the InputError that reading `text` throws ("" if none).
std::string ErrorOf(const std::string& name, const std::string& text) {
  const std::string path = Write(name, text);
  try {
    ReadLabelTable(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

float Distance(RGB a, RGB b) {
  return std::sqrt((a.r - b.r) * (a.r - b.r) + (a.g - b.g) * (a.g - b.g) + (a.b - b.b) * (a.b - b.b));
}

}  // namespace

TEST(LabelTable, ReadsEverySharedDataTable) {
  const fs::path dir(MMRTM_SHARED_DATA_DIR);
  if (!fs::is_directory(dir)) GTEST_SKIP() << "no shared data at " << dir;
  int tables = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string file = e.path().filename().string();
    if (file.size() < 11 || file.substr(file.size() - 11) != "_labels.txt") continue;
    SCOPED_TRACE(file);
    ++tables;
    LabelTable t = ReadLabelTable(e.path().string());
    EXPECT_EQ(t.source, e.path().string());
    ASSERT_FALSE(t.entries.empty());
    // Every non-comment line is one label; none of these files gives colours.
    std::ifstream in(e.path());
    int lines = 0;
    for (std::string l; std::getline(in, l);) {
      const size_t first = l.find_first_not_of(" \t\r");  // some end in CRLF, and with a blank line
      if (first != std::string::npos && l[first] != '#') ++lines;
    }
    EXPECT_EQ((int)t.entries.size(), lines);
    std::set<int> ids;
    for (const LabelEntry& l : t.entries) {
      EXPECT_GT(l.id, 0);
      EXPECT_TRUE(ids.insert(l.id).second);
      EXPECT_FALSE(l.name.empty());
      EXPECT_FALSE(l.hasColor) << l.id << " " << l.name;
      EXPECT_EQ(l.opacity, 1.f);
      EXPECT_EQ(Distance(l.color, DefaultLabelColor(l.id)), 0.f);
      EXPECT_EQ(t.Find(l.id), &l);
    }
  }
  EXPECT_GE(tables, 6);
}

TEST(LabelTable, AtlasCodesAndRemarksAreNotColours) {
  const fs::path dir(MMRTM_SHARED_DATA_DIR);
  if (!fs::is_directory(dir)) GTEST_SKIP() << "no shared data at " << dir;
  LabelTable aal = ReadLabelTable((dir / "mni_colin27_aal_labels.txt").string());
  EXPECT_EQ(aal.entries.size(), 116u);
  ASSERT_NE(aal.Find(1), nullptr);
  EXPECT_EQ(aal.Find(1)->name, "Precentral_L");  // `1 Precentral_L 2001`: 2001 is an AAL code
  EXPECT_FALSE(aal.Find(1)->hasColor);
  EXPECT_EQ(aal.Find(116)->name, "Vermis_10");
  EXPECT_EQ(aal.Find(0), nullptr);
  LabelTable head = ReadLabelTable((dir / "mr_head_labels.txt").string());
  ASSERT_EQ(head.entries.size(), 2u);
  EXPECT_EQ(head.entries[0].name, "brain");  // `1 brain (Brain.nrrd)`
  EXPECT_EQ(head.entries[1].name, "skull");
  EXPECT_FALSE(head.entries[1].hasColor);
}

TEST(LabelTable, ReadsSlicerColorTable) {
  const std::string path = Write("slicer.ctbl",
                                 "# Color table file /tmp/Segmentation-label_ColorTable.ctbl\n"
                                 "# 3 values\n"
                                 "0 Background 0 0 0 0\r\n"
                                 "1 tissue 128 174 128 255\r\n"
                                 "\n"
                                 "   \t\n"
                                 "  2 bone 241 214 145\n"
                                 "7 half 255 0 51 128");  // no final newline
  LabelTable t = ReadLabelTable(path);
  ASSERT_EQ(t.entries.size(), 4u);
  const LabelEntry* bg = t.Find(0);
  ASSERT_NE(bg, nullptr);
  EXPECT_TRUE(bg->hasColor);
  EXPECT_EQ(bg->name, "Background");
  EXPECT_EQ(bg->opacity, 0.f);
  const LabelEntry* tissue = t.Find(1);
  EXPECT_TRUE(tissue->hasColor);
  EXPECT_FLOAT_EQ(tissue->color.r, 128.f / 255);
  EXPECT_FLOAT_EQ(tissue->color.g, 174.f / 255);
  EXPECT_FLOAT_EQ(tissue->color.b, 128.f / 255);
  EXPECT_FLOAT_EQ(tissue->opacity, 1.f);
  const LabelEntry* bone = t.Find(2);  // three values: opaque
  EXPECT_TRUE(bone->hasColor);
  EXPECT_FLOAT_EQ(bone->color.r, 241.f / 255);
  EXPECT_FLOAT_EQ(bone->opacity, 1.f);
  EXPECT_FLOAT_EQ(t.Find(7)->opacity, 128.f / 255);
  EXPECT_FLOAT_EQ(t.Find(7)->color.b, 51.f / 255);
  EXPECT_EQ(t.Find(3), nullptr);
}

TEST(LabelTable, ExtraTokensThatAreNotAColour) {
  LabelTable t = ReadLabelTable(Write("extras.txt",
                                      "1 code 2001\n"
                                      "2 remark (Brain.nrrd)\n"
                                      "3 two 10 20\n"
                                      "4 five 1 2 3 4 5\n"
                                      "5 words 10 20 thirty\n"
                                      "6 plain\n"));
  ASSERT_EQ(t.entries.size(), 6u);
  for (const LabelEntry& e : t.entries) {
    EXPECT_FALSE(e.hasColor) << e.name;
    EXPECT_EQ(Distance(e.color, DefaultLabelColor(e.id)), 0.f) << e.name;
  }
  EXPECT_EQ(t.Find(2)->name, "remark");
}

TEST(LabelTable, ErrorsNameTheFileAndLine) {
  const std::string missing = (TestOutputFolder() / "missing.txt").string();
  fs::remove(missing);
  try {
    ReadLabelTable(missing);
    FAIL() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  struct Case {
    const char* file;
    const char* text;
    const char* expected;  // in the message, after "path:line: "
  } cases[] = {
      {"nonint.txt", "1 a\nx b\n", ":2: expected an integer label id, got 'x'"},
      {"fraction.txt", "1.5 a\n", ":1: expected an integer label id"},
      {"negative.txt", "# c\n-3 a\n", ":2: label id -3 is negative"},
      {"duplicate.txt", "1 a\n2 b\n\n1 c\n", ":4: duplicate label id 1 (first on line 1)"},
      {"noname.txt", "1 a\n5\n", ":2: label 5 has no name"},
      {"range.txt", "1 a 300 0 0\n", ":1: colour value '300' of label 1 is not an integer in 0-255"},
      {"negcolour.txt", "1 a 0 -1 0 255\n", ":1: colour value '-1'"},
      {"alpharange.txt", "1 a 0 0 0 256\n", ":1: colour value '256'"},
      {"floatcolour.txt", "1 a 0.5 0.2 0.1\n", ":1: colour value '0.5' of label 1 is not an integer in 0-255"},
      {"huge.txt", "99999999999 a\n", ":1: label id 99999999999 is too large"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string message = ErrorOf(c.file, c.text);
    const std::string path = (TestOutputFolder() / c.file).string();
    EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
    EXPECT_NE(message.find(path + c.expected), std::string::npos) << message;
  }
}

TEST(LabelTable, DefaultColorsAreDeterministicAndDistinct) {
  EXPECT_EQ(Distance(DefaultLabelColor(0), RGB(0.f)), 0.f);
  float closest = 1e9f, closestNeighbour = 1e9f;
  for (int a = 1; a <= 64; ++a) {
    const RGB c = DefaultLabelColor(a);
    EXPECT_EQ(Distance(c, DefaultLabelColor(a)), 0.f);
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_GE(c[ch], 0.f);
      EXPECT_LE(c[ch], 1.f);
    }
    EXPECT_GT(std::max({c.r, c.g, c.b}), 0.5f) << a;  // never murky
    if (a > 1) closestNeighbour = std::min(closestNeighbour, Distance(c, DefaultLabelColor(a - 1)));
    for (int b = 1; b < a; ++b) closest = std::min(closest, Distance(c, DefaultLabelColor(b)));
  }
  EXPECT_GT(closestNeighbour, 0.3f);
  EXPECT_GT(closest, 0.02f);
  EXPECT_NO_THROW(DefaultLabelColor(1 << 30));
}
