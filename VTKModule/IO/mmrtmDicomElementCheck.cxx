// A walk over a DICOM file's data elements that checks each stated length
// against the bytes left in the file, before GDCM reads it. GDCM allocates
// an element's value at the length the file states (one corrupt length made
// it ask for 2.2 GB for a 0.5 MB slice), and Debian builds it with its
// assertions on, which abort the program on a file cut off in an element
// header (all found by fuzzing). The walk reads only tags and lengths
// (values are skipped with seeks), so it costs little next to GDCM's read.
#include "mmrtmVolumeLoaderInternal.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace mmrtm
{
namespace
{

// The value representations of DICOM PS3.5 (what GDCM's VR::IsValid takes).
bool IsVr(const unsigned char* p)
{
  static const char* kVrs[] = { "AE", "AS", "AT", "CS", "DA", "DS", "DT", "FD", "FL", "IS", "LO", "LT", "OB", "OD",
    "OF", "OL", "OV", "OW", "PN", "SH", "SL", "SQ", "SS", "ST", "SV", "TM", "UC", "UI", "UL", "UN", "UR", "US", "UT",
    "UV" };
  for (const char* v : kVrs)
    if (p[0] == (unsigned char)v[0] && p[1] == (unsigned char)v[1])
      return true;
  return false;
}

// VRs whose explicit-VR length is 4 bytes after 2 reserved ones.
bool HasLongLength(const char vr[2])
{
  static const char* kLong[] = { "OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN", "UR", "UT", "UV" };
  for (const char* v : kLong)
    if (vr[0] == v[0] && vr[1] == v[1])
      return true;
  return false;
}

uint16_t U16(const unsigned char* p, bool big)
{
  return big ? uint16_t(p[0] << 8 | p[1]) : uint16_t(p[0] | p[1] << 8);
}
uint32_t U32(const unsigned char* p, bool big)
{
  return big ? uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3])
             : uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

std::string Hex4(unsigned v)
{
  char text[8];
  std::snprintf(text, sizeof text, "%04X", v & 0xFFFF);
  return text;
}

// How the dataset is encoded.
struct Syntax
{
  bool explicitVr = true;
  bool bigEndian = false;
};

// A file without the "DICM" preamble: the encoding guessed from its first
// element, as GDCM's FileMetaInformation::ReadCompat does; nullopt where
// GDCM gives up on the file as not DICOM (a text file in the folder).
std::optional<Syntax> GuessSyntax(const unsigned char* first)
{
  const unsigned group = U16(first, false), element = U16(first + 2, false);
  // Outside the meta group GDCM asks VR::GetVRType, which also knows "??"
  // (its name for an invalid VR): a file starting with one was read as
  // explicit VR, and GDCM asserted on it (a fuzz finding).
  const bool vr = IsVr(first + 4) || (group != 0x0002 && first[4] == '?' && first[5] == '?');
  if (group == 0x0002 || group == 0x0008 || element == 0x0010)
    return Syntax{ vr, false };
  if (group == 0x0800)
    return Syntax{ vr, true }; // group 8, big endian (ACR-NEMA)
  if (vr)
    return Syntax{ true, group > 0xFF || element > 0xFF };
  return std::nullopt;
}

// A JPEG 2000 codestream (a fragment of encapsulated pixel data that starts
// with the SOC and SIZ markers) must have the image size the dataset states:
// OpenJPEG allocates the size its SIZ marker promises (one flipped bit of
// Xsiz made it ask for 2 GB for a 512 x 512 slice: a fuzz finding). ""
// when it agrees, or for a fragment that is not the start of a codestream.
std::string CheckJpeg2000Size(std::ifstream& in, uint64_t pos, unsigned rows, unsigned columns, unsigned samples)
{
  unsigned char m[42];
  in.clear();
  in.seekg((std::streamoff)pos);
  if (!in.read(reinterpret_cast<char*>(m), sizeof m))
    return "";
  if (!(m[0] == 0xFF && m[1] == 0x4F && m[2] == 0xFF && m[3] == 0x51))
    return "";
  const uint32_t x = U32(m + 8, true), y = U32(m + 12, true), x0 = U32(m + 16, true), y0 = U32(m + 20, true);
  const uint32_t tileX = U32(m + 24, true), tileY = U32(m + 28, true);
  const unsigned components = U16(m + 40, true);
  const uint64_t width = x > x0 ? x - x0 : 0, height = y > y0 ? y - y0 : 0;
  if (tileX == 0 || tileY == 0 || width != columns || height != rows || components != samples)
    return "its JPEG 2000 codestream says " + std::to_string(width) + " x " + std::to_string(height) + " x " +
      std::to_string(components) + " samples (tiles " + std::to_string(tileX) + " x " + std::to_string(tileY) +
      ") where the dataset says " + std::to_string(columns) + " x " + std::to_string(rows) + " x " +
      std::to_string(samples) + " (corrupt)";
  return "";
}

} // namespace

std::string CheckDicomElementLengths(const std::string& file)
{
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in)
    return ""; // the reader names an unreadable file
  const uint64_t size = (uint64_t)in.tellg();
  unsigned char b[12];
  auto readAt = [&](uint64_t pos, size_t n)
  {
    in.clear();
    in.seekg((std::streamoff)pos);
    return (bool)in.read(reinterpret_cast<char*>(b), (std::streamsize)n);
  };
  uint64_t pos = 0;
  const bool part10 = size >= 132 && readAt(128, 4) && std::memcmp(b, "DICM", 4) == 0;
  bool inMeta = part10; // the meta group, always explicit little endian
  Syntax syntax;        // of the dataset
  if (part10)
  {
    pos = 132;
  }
  else if (size < 6)
  {
    // Too short for a tag and a VR. GDCM rejects it without a fuss, but for
    // a tag it takes for DICOM's (GuessSyntax's first rule): then it
    // asserts reading the rest of the element's header (a fuzz finding).
    if (size >= 4 && readAt(0, 4) &&
      (U16(b, false) == 0x0002 || U16(b, false) == 0x0008 || U16(b + 2, false) == 0x0010))
      return "the file ends inside a data element's header at byte 0 (truncated)";
    return "";
  }
  else if (!readAt(0, 6))
  {
    return "";
  }
  else
  {
    const std::optional<Syntax> guess = GuessSyntax(b);
    if (!guess)
      return ""; // not DICOM: GDCM skips it
    syntax = *guess;
    inMeta = U16(b, false) == 0x0002;
  }
  bool fragments = false;     // inside encapsulated pixel data
  std::vector<uint64_t> ends; // where the sequences and items of defined length the walk is in end
  std::string transferSyntax;
  unsigned rows = 0, columns = 0, samples = 1; // (0028,0010), (0028,0011), (0028,0002) as read
  while (pos + 8 <= size)
  {
    while (!ends.empty() && pos >= ends.back())
      ends.pop_back(); // left them
    if (!readAt(pos, 8))
      return "";
    if (inMeta && U16(b, false) != 0x0002)
    {
      inMeta = false;
      // A deflated dataset's element lengths are inside the zlib stream,
      // where this walk cannot see them: GDCM inflated one and allocated
      // the 1.5 GB it stated (a fuzz finding). Refused until the walk
      // inflates it first; no CT or MR series here uses it.
      if (transferSyntax == "1.2.840.10008.1.2.1.99")
        return "the dataset is deflate compressed (transfer syntax 1.2.840.10008.1.2.1.99), which this reader "
               "does not support";
      if (!transferSyntax.empty())
      {
        syntax.explicitVr = transferSyntax != "1.2.840.10008.1.2";
        syntax.bigEndian = transferSyntax == "1.2.840.10008.1.2.2";
      }
      else
      {
        syntax.explicitVr = IsVr(b + 4); // a meta group without a transfer syntax: guess
      }
    }
    const bool big = !inMeta && syntax.bigEndian;
    const unsigned group = U16(b, big), element = U16(b + 2, big);
    // The meta group is explicit VR by the standard; without a preamble
    // GDCM asserts on one of its elements that has no VR (a fuzz finding).
    if (inMeta && !part10 && !IsVr(b + 4))
      return "element (" + Hex4(group) + "," + Hex4(element) + ") at byte " + std::to_string(pos) +
        " of the file meta information has no value representation (corrupt)";
    uint64_t header = 8;
    uint64_t length = U32(b + 4, big);
    char vr[2] = { 0, 0 };
    if (group != 0xFFFE && (inMeta || syntax.explicitVr) && IsVr(b + 4))
    {
      std::memcpy(vr, b + 4, 2);
      if (HasLongLength(vr))
      {
        if (pos + 12 > size || !readAt(pos, 12))
          break; // reported below as cut off
        header = 12;
        length = U32(b + 8, big);
      }
      else
      {
        length = U16(b + 6, big);
      }
    }
    else if (group != 0xFFFE && !inMeta && syntax.explicitVr)
    {
      // Explicit VR with two bytes that are no VR: GDCM then reads the
      // dataset again by its fallbacks for broken files ("VR16 explicit",
      // implicit VR), and on fuzzed files those asserted (on a few bytes
      // left, on a tag (0000,0000), on a stream left bad) or allocated
      // gigabytes (fuzz findings). Such a file is refused.
      return "element (" + Hex4(group) + "," + Hex4(element) + ") at byte " + std::to_string(pos) +
        " has no valid value representation, in a dataset encoded with explicit ones (corrupt)";
    }
    const std::string where = "element (" + Hex4(group) + "," + Hex4(element) + ") at byte " + std::to_string(pos);
    pos += header;
    // GDCM asserts (aborts) on these in the meta group.
    if (group == 0x0002 && (length == 0xFFFFFFFFu || (vr[0] == 'S' && vr[1] == 'Q')))
      return where + " is a sequence or has an undefined length in the file meta information (corrupt)";
    if (group == 0x7FE0 && element == 0x0010 && length == 0xFFFFFFFFu)
    {
      if (vr[0] && !(vr[0] == 'O' && (vr[1] == 'B' || vr[1] == 'W'))) // GDCM asserts OB or OW
        return where + ": encapsulated pixel data must be OB or OW, not " + std::string(vr, 2) + " (corrupt)";
      fragments = true; // encapsulated (compressed) pixel data: items of raw bytes follow
      continue;
    }
    if (group == 0xFFFE && element == 0xE0DD)
      fragments = false; // a sequence delimiter ends them
    if (fragments && group == 0xFFFE && element == 0xE000 && length >= 42 && length <= size - pos)
    {
      const std::string problem = CheckJpeg2000Size(in, pos, rows, columns, samples);
      if (!problem.empty())
        return where + ": " + problem;
    }
    // An undefined length belongs to sequences (SQ, UN) and encapsulated
    // pixel data; GDCM asserts on one in any other explicit VR element (a
    // fuzz finding).
    if (length == 0xFFFFFFFFu && vr[0] && group != 0xFFFE && !(vr[0] == 'S' && vr[1] == 'Q') &&
      !(vr[0] == 'U' && vr[1] == 'N'))
      return where + " (" + std::string(vr, 2) + ") has an undefined length, which only sequences and " +
        "encapsulated pixel data may have (corrupt)";
    if (length == 0xFFFFFFFFu)
      continue; // undefined length: its items and delimiters follow
    if (length > size - pos)
      return where + " says its value is " + std::to_string(length) + " bytes, but only " + std::to_string(size - pos) +
        " are left in the file (truncated or corrupt)";
    // GDCM reads a sequence or an item of defined length within that
    // length: an element that ran past its end made GDCM fail and assert
    // (a fuzz finding).
    if (!ends.empty() && pos + length > ends.back())
      return where + " runs past the end of the sequence or item that holds it (corrupt)";
    // Items of a sequence and sequences: their elements follow and are
    // checked in turn. A fragment of pixel data is bytes: skipped.
    if ((group == 0xFFFE && !fragments) || (vr[0] == 'S' && vr[1] == 'Q'))
    {
      ends.push_back(pos + length);
      continue;
    }
    if (!vr[0] && length >= 8 && readAt(pos, 4) && U16(b, big) == 0xFFFE && U16(b + 2, big) == 0xE000)
    {
      ends.push_back(pos + length);
      continue; // a sequence in implicit VR: its first item follows
    }
    if (group == 0x0028 && (element == 0x0010 || element == 0x0011 || element == 0x0002) && length == 2 &&
      readAt(pos, 2))
    {
      const unsigned value = U16(b, big);
      (element == 0x0010 ? rows : element == 0x0011 ? columns : samples) = value;
    }
    if (group == 0x0002 && element == 0x0010 && length <= 64)
    {
      char uid[65] = {};
      in.clear();
      in.seekg((std::streamoff)pos);
      in.read(uid, (std::streamsize)length);
      transferSyntax = Trim(std::string(uid, std::strlen(uid)));
    }
    pos += length;
  }
  // Cut off in an element header: GDCM asserts on a few stray bytes after
  // the meta group or at the start of a file, on a long VR's header cut
  // short, and on 4 to 7 bytes after a dataset (it reads a tag, then fails
  // on the rest: a fuzz finding). Up to 3 bytes after a dataset are left
  // alone: some writers pad, and GDCM stops there quietly.
  if (pos < size && (inMeta || pos == 0 || size - pos >= 4))
    return "the file ends inside a data element's header at byte " + std::to_string(pos) + " (truncated)";
  // A file that ends with its meta group, no dataset after it: GDCM asserts
  // reading the element it expects next (a fuzz finding).
  if (inMeta)
    return "the file ends after its meta information (group 0002): no dataset follows (truncated)";
  return "";
}

} // namespace mmrtm
