// InVesalius projects (.inv3): a gzip-compressed tar read with zlib, its
// main.plist parsed, and the raw voxel file it names. The gzip reader, the tar
// reader and the plist parser are private to this file.
#include "mmrtmVolumeLoaderInternal.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace mmrtm
{

// A gzip-compressed tar holding main.plist (Apple XML plist) and the raw
// little-endian voxel file it names (x fastest). The project keeps no
// patient orientation. Its rows run from posterior to anterior (the face of
// Cranium.inv3 is at the last rows, its head holder at the first), the
// opposite of DICOM's: the y axis is flipped so that +y is posterior (LPS),
// and a camera on the anterior side sees the face. (ct_head_cranium.nrrd
// holds the same voxels with an identity direction; it shows the face at +y.)

namespace
{

// Sequential reads through zlib (plain, uncompressed files read as they are).
class GzipReader
{
public:
  explicit GzipReader(const std::string& path)
    : path_(path)
    , file_(gzopen(path.c_str(), "rb"))
  {
    if (!file_)
      throw InputError(path + ": cannot open");
  }
  ~GzipReader() { gzclose(file_); }
  GzipReader(const GzipReader&) = delete;
  GzipReader& operator=(const GzipReader&) = delete;

  // Reads up to n bytes; fewer only at the end of the data. Throws on
  // corrupt data, on a CRC mismatch at the end of the stream and on a stream
  // cut short (zlib reports that as an end of data with Z_BUF_ERROR set).
  uint64_t Read(void* buffer, uint64_t n)
  {
    uint64_t done = 0;
    while (done < n)
    {
      const unsigned chunk = (unsigned)std::min<uint64_t>(n - done, 1u << 30);
      const int got = gzread(file_, static_cast<char*>(buffer) + done, chunk);
      int code = Z_OK;
      const char* msg = gzerror(file_, &code);
      if (got < 0 || code != Z_OK)
      {
        std::string what = msg ? msg : "zlib error";
        if (what.rfind(path_ + ": ", 0) == 0)
          what = what.substr(path_.size() + 2); // zlib prefixes the path
        throw InputError(path_ + ": corrupt or truncated gzip data (" + what + ")");
      }
      if (got == 0)
        break;
      done += (uint64_t)got;
    }
    return done;
  }

  // Skips n bytes; returns how many there were.
  uint64_t Skip(uint64_t n)
  {
    std::vector<char> scratch(1 << 16);
    uint64_t done = 0;
    while (done < n)
    {
      const uint64_t got = Read(scratch.data(), std::min<uint64_t>(n - done, scratch.size()));
      if (got == 0)
        break;
      done += got;
    }
    return done;
  }

private:
  std::string path_;
  gzFile file_;
};

struct TarEntry
{
  std::string name;
  uint64_t size = 0;
  char type = '0';
};

// Octal field (NUL/space padded), or GNU base-256 when the high bit is set.
uint64_t TarNumber(const char* field, size_t width)
{
  if ((unsigned char)field[0] & 0x80)
  {
    uint64_t v = (unsigned char)field[0] & 0x7f;
    for (size_t i = 1; i < width; ++i)
      v = (v << 8) | (unsigned char)field[i];
    return v;
  }
  uint64_t v = 0;
  for (size_t i = 0; i < width && field[i]; ++i)
    if (field[i] >= '0' && field[i] <= '7')
      v = v * 8 + (uint64_t)(field[i] - '0');
  return v;
}

std::string TarString(const char* field, size_t width)
{
  return std::string(field, strnlen(field, width));
}

// Reads the next 512-byte header; false at the end-of-archive block or the
// end of the data. Throws on a partial or damaged header.
bool ReadTarHeader(GzipReader& in, const std::string& path, TarEntry& entry)
{
  char h[512];
  const uint64_t got = in.Read(h, sizeof h);
  if (got == 0)
    return false;
  if (got < sizeof h)
    throw InputError(path + ": truncated archive (partial tar header)");
  if (std::all_of(h, h + 512, [](char c) { return c == 0; }))
    return false;
  // The checksum sums the header bytes with the checksum field read as spaces.
  unsigned sum = 0;
  for (int i = 0; i < 512; ++i)
    sum += (i >= 148 && i < 156) ? ' ' : (unsigned char)h[i];
  if (sum != TarNumber(h + 148, 8))
    throw InputError(path + ": not a valid tar archive (bad header checksum)");
  entry.name = TarString(h, 100);
  if (std::memcmp(h + 257, "ustar", 5) == 0 && h[345])
    entry.name = TarString(h + 345, 155) + "/" + entry.name;
  entry.size = TarNumber(h + 124, 12);
  entry.type = h[156];
  return true;
}

// Reads the members after the current one to the end of the data, so that a
// damaged archive is an error even when the member we need is intact (and
// zlib checks the stream's CRC at its end).
void VerifyRestOfArchive(GzipReader& in, const std::string& path)
{
  TarEntry entry;
  while (ReadTarHeader(in, path, entry))
  {
    const uint64_t padded = (entry.size + 511) / 512 * 512;
    if (in.Skip(padded) != padded)
      throw InputError(path + ": truncated archive (" + entry.name + " is cut short)");
  }
  in.Skip(std::numeric_limits<uint64_t>::max()); // trailing zero blocks up to the gzip end
}

// The bytes of the first regular member whose base name is `baseName`.
// Throws if it is absent, bigger than maxSize, or cut short; with
// `verifyArchive`, also if the rest of the archive is damaged.
std::vector<uint8_t> ReadTarMember(
  const std::string& path, const std::string& baseName, uint64_t maxSize, bool verifyArchive)
{
  GzipReader in(path);
  TarEntry entry;
  std::string longName; // from a GNU 'L' entry, naming the entry after it
  while (ReadTarHeader(in, path, entry))
  {
    const uint64_t padded = (entry.size + 511) / 512 * 512;
    if (entry.type == 'L')
    {
      std::vector<char> name(entry.size);
      if (in.Read(name.data(), entry.size) != entry.size)
        break;
      longName = TarString(name.data(), name.size());
      in.Skip(padded - entry.size);
      continue;
    }
    const std::string name = longName.empty() ? entry.name : longName;
    longName.clear();
    const bool regular = entry.type == '0' || entry.type == '\0';
    if (regular && fs::path(name).filename().string() == baseName)
    {
      if (entry.size > maxSize)
        throw InputError(path + ": " + baseName + " is " + std::to_string(entry.size) + " bytes, expected at most " +
          std::to_string(maxSize));
      std::vector<uint8_t> data(entry.size);
      if (in.Read(data.data(), entry.size) != entry.size || in.Skip(padded - entry.size) != padded - entry.size)
        throw InputError(path + ": truncated archive (" + baseName + " is cut short)");
      if (verifyArchive)
        VerifyRestOfArchive(in, path);
      return data;
    }
    if (in.Skip(padded) != padded)
      break;
  }
  throw InputError(path + ": no " + baseName + " in the archive (truncated, or not an InVesalius project?)");
}

// A parsed Apple XML plist value: a dict, an array or a scalar's text.
struct PlistValue
{
  std::string kind; // dict, array, string, integer, real, true, false, date, data
  std::string text;
  std::vector<std::pair<std::string, PlistValue>> entries; // dict
  std::vector<PlistValue> items;                           // array

  const PlistValue* Find(const std::string& key) const
  {
    for (const auto& e : entries)
      if (e.first == key)
        return &e.second;
    return nullptr;
  }
};

// A small parser for the plist subset InVesalius writes (no attributes on
// values, no CDATA). Enough to read main.plist; not a general XML parser.
class PlistParser
{
public:
  PlistParser(const std::string& xml, std::string where)
    : xml_(xml)
    , where_(std::move(where))
  {
  }

  PlistValue ParseDocument()
  {
    bool selfClosing = false;
    std::string tag = NextTag(&selfClosing);
    if (tag == "plist")
      tag = NextTag(&selfClosing);
    return ParseValue(tag, selfClosing, 0);
  }

private:
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + ": bad plist: " + what); }

  // The next element tag's name ("/name" for a closing tag), skipping text,
  // the XML declaration, DOCTYPE and comments.
  std::string NextTag(bool* selfClosing)
  {
    for (;;)
    {
      const size_t open = xml_.find('<', pos_);
      if (open == std::string::npos)
        Fail("unexpected end of document");
      if (xml_.compare(open, 4, "<!--") == 0)
      {
        pos_ = SkipPast(open, "-->");
      }
      else if (xml_.compare(open, 2, "<?") == 0 || xml_.compare(open, 2, "<!") == 0)
      {
        pos_ = SkipPast(open, ">");
      }
      else
      {
        const size_t close = xml_.find('>', open);
        if (close == std::string::npos)
          Fail("unterminated tag");
        std::string body = xml_.substr(open + 1, close - open - 1);
        *selfClosing = !body.empty() && body.back() == '/';
        if (*selfClosing)
          body.pop_back();
        pos_ = close + 1;
        return Trim(body.substr(0, body.find_first_of(" \t\r\n")));
      }
    }
  }

  size_t SkipPast(size_t from, const char* end)
  {
    const size_t at = xml_.find(end, from);
    if (at == std::string::npos)
      Fail("unterminated markup");
    return at + std::strlen(end);
  }

  // The text up to </name>, with the predefined XML entities decoded.
  std::string ReadText(const std::string& name)
  {
    const std::string close = "</" + name + ">";
    const size_t at = xml_.find(close, pos_);
    if (at == std::string::npos)
      Fail("no " + close);
    std::string raw = xml_.substr(pos_, at - pos_), text;
    pos_ = at + close.size();
    static const std::pair<const char*, char> kEntities[] = { { "&lt;", '<' }, { "&gt;", '>' }, { "&amp;", '&' },
      { "&quot;", '"' }, { "&apos;", '\'' } };
    for (size_t i = 0; i < raw.size();)
    {
      bool decoded = false;
      for (const auto& [entity, c] : kEntities)
        if (raw.compare(i, std::strlen(entity), entity) == 0)
        {
          text += c;
          i += std::strlen(entity);
          decoded = true;
          break;
        }
      if (!decoded)
        text += raw[i++];
    }
    return text;
  }

  PlistValue ParseValue(const std::string& tag, bool selfClosing, int depth)
  {
    if (depth > 64)
      Fail("nested too deeply");
    PlistValue v;
    v.kind = tag;
    bool childSelfClosing = false;
    if (tag == "dict")
    {
      while (!selfClosing)
      {
        const std::string keyTag = NextTag(&childSelfClosing);
        if (keyTag == "/dict")
          break;
        if (keyTag != "key")
          Fail("expected <key> in <dict>, found <" + keyTag + ">");
        const std::string key = childSelfClosing ? "" : ReadText("key");
        const std::string valueTag = NextTag(&childSelfClosing);
        v.entries.emplace_back(key, ParseValue(valueTag, childSelfClosing, depth + 1));
      }
    }
    else if (tag == "array")
    {
      while (!selfClosing)
      {
        const std::string itemTag = NextTag(&childSelfClosing);
        if (itemTag == "/array")
          break;
        v.items.push_back(ParseValue(itemTag, childSelfClosing, depth + 1));
      }
    }
    else if (tag == "true" || tag == "false")
    {
      v.text = tag;
    }
    else if (tag == "string" || tag == "integer" || tag == "real" || tag == "date" || tag == "data")
    {
      if (!selfClosing)
        v.text = ReadText(tag);
    }
    else
    {
      Fail("unexpected <" + tag + ">");
    }
    return v;
  }

  const std::string& xml_;
  std::string where_;
  size_t pos_ = 0;
};

// `n` numbers from a plist array of <integer>/<real>.
std::vector<double> PlistNumbers(const PlistValue* v, size_t n, const std::string& what, const std::string& where)
{
  if (!v || v->kind != "array" || v->items.size() != n)
    throw InputError(where + ": '" + what + "' is not an array of " + std::to_string(n) + " numbers");
  std::vector<double> out;
  for (const PlistValue& item : v->items)
  {
    char* end = nullptr;
    const double x = std::strtod(item.text.c_str(), &end);
    if ((item.kind != "integer" && item.kind != "real") || end == item.text.c_str())
      throw InputError(where + ": '" + what + "' holds a non-number");
    out.push_back(x);
  }
  return out;
}

std::string PlistString(const PlistValue* v, const std::string& what, const std::string& where)
{
  if (!v || v->kind != "string" || v->text.empty())
    throw InputError(where + ": no '" + what + "' string");
  return v->text;
}

// numpy dtype names as InVesalius writes them.
std::pair<SourceType, int> NumpyType(const std::string& dtype, const std::string& where)
{
  static const std::map<std::string, std::pair<SourceType, int>> kTypes = { { "int8", { SourceType::Int8, 1 } },
    { "uint8", { SourceType::UInt8, 1 } }, { "int16", { SourceType::Int16, 2 } },
    { "uint16", { SourceType::UInt16, 2 } }, { "int32", { SourceType::Int32, 4 } },
    { "uint32", { SourceType::UInt32, 4 } }, { "int64", { SourceType::Int64, 8 } },
    { "uint64", { SourceType::UInt64, 8 } }, { "float32", { SourceType::Float32, 4 } },
    { "float64", { SourceType::Float64, 8 } } };
  auto it = kTypes.find(dtype);
  if (it == kTypes.end())
    throw InputError(where + ": unsupported matrix dtype '" + dtype + "'");
  return it->second;
}

} // namespace

void LoadInVesalius(const std::string& path, HostVolume& out, const VolumeLoadOptions& /*options*/)
{
  const std::vector<uint8_t> plistBytes = ReadTarMember(path, "main.plist", 16u << 20, false);
  const std::string where = path + ": main.plist";
  const PlistValue root = PlistParser(std::string(plistBytes.begin(), plistBytes.end()), where).ParseDocument();
  const PlistValue* matrix = root.Find("matrix");
  if (!matrix || matrix->kind != "dict")
    throw InputError(where + ": no 'matrix' dict");
  const auto [type, typeSize] = NumpyType(PlistString(matrix->Find("dtype"), "dtype", where), where);
  const std::string dataName = PlistString(matrix->Find("filename"), "filename", where);
  const std::vector<double> shape = PlistNumbers(matrix->Find("shape"), 3, "shape", where);    // z, y, x
  const std::vector<double> spacing = PlistNumbers(root.Find("spacing"), 3, "spacing", where); // x, y, z

  for (int a = 0; a < 3; ++a)
  {
    const double n = shape[2 - a];
    if (!(n >= 1 && n <= std::numeric_limits<int>::max() && n == std::floor(n)))
      throw InputError(where + ": bad matrix shape");
    out.dims[a] = (int)n;
  }
  const uint64_t bytes = (uint64_t)out.VoxelCount() * (uint64_t)typeSize;
  CheckMemoryAvailable(path, 2.0 * (double)bytes, "the voxel matrix");
  std::vector<uint8_t> raw = ReadTarMember(path, fs::path(dataName).filename().string(), bytes, true);
  if (raw.size() != bytes)
    throw InputError(path + ": " + dataName + " holds " + std::to_string(raw.size()) + " bytes, expected " +
      std::to_string(bytes) + " for the matrix shape");
  // The .dat is little endian, as is every platform this project builds on.
  // A type the tracer samples as it is keeps the matrix as read (no copy).
  if (const std::optional<VoxelType> native = NativeVoxelType(type))
  {
    out.type = *native;
    out.voxels = std::move(raw);
  }
  else
  {
    StoreVoxels(raw.data(), type, out.VoxelCount(), Rescale{}, out);
  }
  out.indexToWorld = IndexToWorld(
    { 0, (out.dims[1] - 1) * spacing[1], 0 }, { spacing[0], spacing[1], spacing[2] }, { 1, 0, 0, 0, -1, 0, 0, 0, 1 });
}

} // namespace mmrtm
