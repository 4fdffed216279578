// A walk over a DICOM file's data elements that checks each stated length
// against the bytes left in the file, before GDCM reads it. GDCM allocates
// an element's value at the length the file states: one corrupt length made
// it ask for 2.2 GB for a 0.5 MB slice (found by fuzzing). The walk reads
// only tags and lengths (values are skipped with seeks), so it costs little
// next to GDCM's own read.
#include "mmrtmVolumeLoaderInternal.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace mmrtm {
namespace {

// VRs whose explicit-VR length is 4 bytes after 2 reserved ones.
bool HasLongLength(const char vr[2]) {
  static const char* kLong[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN", "UR", "UT", "UV"};
  for (const char* v : kLong)
    if (vr[0] == v[0] && vr[1] == v[1]) return true;
  return false;
}

bool IsVr(const char vr[2]) { return vr[0] >= 'A' && vr[0] <= 'Z' && vr[1] >= 'A' && vr[1] <= 'Z'; }

uint16_t U16(const unsigned char* p) { return uint16_t(p[0] | p[1] << 8); }
uint32_t U32(const unsigned char* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

std::string Hex4(unsigned v) {
  char text[8];
  std::snprintf(text, sizeof text, "%04X", v & 0xFFFF);
  return text;
}

}  // namespace

std::string CheckDicomElementLengths(const std::string& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return "";  // the reader names an unreadable file
  const uint64_t size = (uint64_t)in.tellg();
  unsigned char b[12];
  auto readAt = [&](uint64_t pos, size_t n) {
    in.clear();
    in.seekg((std::streamoff)pos);
    return (bool)in.read(reinterpret_cast<char*>(b), (std::streamsize)n);
  };
  uint64_t pos = 0;
  if (size >= 132 && readAt(128, 4) && std::memcmp(b, "DICM", 4) == 0) pos = 132;
  // Without the preamble, judge only what starts like a dataset (group 2 or
  // 8, little endian); anything else is left to GDCM, which rejects it.
  if (pos == 0 && !(readAt(0, 2) && (U16(b) == 0x0002 || U16(b) == 0x0008))) return "";

  bool explicitVr = true;  // the meta group always is; the dataset as its transfer syntax says
  bool inMeta = true;
  bool fragments = false;  // inside encapsulated pixel data
  std::string transferSyntax;
  while (pos + 8 <= size) {
    if (!readAt(pos, 8)) return "";
    const unsigned group = U16(b), element = U16(b + 2);
    if (inMeta && group != 0x0002) {
      inMeta = false;
      // Big endian and deflated datasets are left to GDCM (rare; the walk
      // would need their own decoding).
      if (transferSyntax == "1.2.840.10008.1.2.2" || transferSyntax == "1.2.840.10008.1.2.1.99") return "";
      explicitVr = transferSyntax != "1.2.840.10008.1.2";
      if (transferSyntax.empty()) explicitVr = IsVr(reinterpret_cast<const char*>(b + 4));  // no meta group: guess
    }
    uint64_t header = 8;
    uint64_t length = U32(b + 4);
    char vr[2] = {0, 0};
    if (group != 0xFFFE && (explicitVr || inMeta) && IsVr(reinterpret_cast<const char*>(b + 4))) {
      std::memcpy(vr, b + 4, 2);
      if (HasLongLength(vr)) {
        if (pos + 12 > size || !readAt(pos, 12)) break;  // reported below as cut off
        header = 12;
        length = U32(b + 8);
      } else {
        length = U16(b + 6);
      }
    }
    const std::string where = "element (" + Hex4(group) + "," + Hex4(element) + ") at byte " + std::to_string(pos);
    pos += header;
    if (group == 0x7FE0 && element == 0x0010 && length == 0xFFFFFFFFu) {
      fragments = true;  // encapsulated (compressed) pixel data: items of raw bytes follow
      continue;
    }
    if (group == 0xFFFE && element == 0xE0DD) fragments = false;  // a sequence delimiter ends them
    // GDCM asserts (aborts) on these in the meta group.
    if (group == 0x0002 && (length == 0xFFFFFFFFu || (vr[0] == 'S' && vr[1] == 'Q')))
      return where + " is a sequence or has an undefined length in the file meta information (corrupt)";
    if (length == 0xFFFFFFFFu) continue;  // undefined length: its items and delimiters follow
    if (length > size - pos)
      return where + " says its value is " + std::to_string(length) + " bytes, but only " +
             std::to_string(size - pos) + " are left in the file (truncated or corrupt)";
    // Items of a sequence and sequences: their elements follow and are
    // checked in turn. A fragment of pixel data is bytes: skipped.
    if ((group == 0xFFFE && !fragments) || (vr[0] == 'S' && vr[1] == 'Q')) continue;
    if (!vr[0] && length >= 8 && readAt(pos, 4) && U16(b) == 0xFFFE && U16(b + 2) == 0xE000) continue;  // implicit SQ
    if (group == 0x0002 && element == 0x0010 && length <= 64) {
      char uid[65] = {};
      in.clear();
      in.seekg((std::streamoff)pos);
      in.read(uid, (std::streamsize)length);
      transferSyntax = Trim(std::string(uid, std::strlen(uid)));
    }
    pos += length;
  }
  // A file cut off inside the meta group, or inside an element header: GDCM
  // asserts on a few stray bytes right after the meta group. (A few bytes
  // after the dataset are left alone: some writers pad files.)
  if (pos < size && (inMeta || pos + 8 <= size))
    return "the file ends inside a data element's header at byte " + std::to_string(pos) + " (truncated)";
  return "";
}

}  // namespace mmrtm
