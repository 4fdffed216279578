// MetaImage volumes (.mha, .mhd): uncompressed 3D voxels of a native type
// read straight into the volume (ReadRawVoxels), the others through
// vtkMetaImageReader with a check that the voxel data is all there; the
// geometry (Offset, ElementSpacing, TransformMatrix) read from the header
// text.
#include "mmrtmVolumeLoaderInternal.h"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMetaImageReader.h>
#include <vtkNew.h>

namespace fs = std::filesystem;

namespace mmrtm
{

// vtkMetaImageReader ignores TransformMatrix, so the geometry comes from the
// header text. As in ITK, TransformMatrix lists the direction of axis 0, then
// of axis 1, then of axis 2, in LPS; AnatomicalOrientation is ignored (ITK
// does the same on reading).

namespace
{

struct MetaImageHeader
{
  std::map<std::string, std::string> fields; // "Key = Value" pairs
  uint64_t size = 0;                         // bytes up to and including the ElementDataFile line
};

MetaImageHeader ReadMetaImageHeader(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open");
  MetaImageHeader h;
  std::string line;
  int number = 0;
  while (h.size < (1u << 20) && std::getline(in, line))
  {
    h.size += line.size() + 1;
    ++number;
    // The header must read the same to metaio as to us: binary bytes in it
    // (metaio then read on past them, to a later ElementDataFile a fuzz
    // input put there) and a key given twice are errors.
    for (unsigned char c : line)
      if (c < 0x20 && c != '\t' && c != '\r')
        throw InputError(path + ": line " + std::to_string(number) +
          " of the MetaImage header holds a control character (binary data in the header?)");
    // metaio ends a key at '=' or ':' and reads its value from past the
    // next one, on a later line when this one has none: a garbled line
    // without either hid the next ElementDataFile from metaio and showed it
    // another one (a fuzz finding). So every line that is not blank is a
    // "Key = Value" (or "Key: Value") pair, as metaio reads it.
    const size_t eq = line.find_first_of("=:");
    if (eq == std::string::npos)
    {
      if (Trim(line).empty())
        continue;
      throw InputError(path + ": line " + std::to_string(number) + " of the MetaImage header has no '=' (" +
        Trim(line).substr(0, 40) + ")");
    }
    const std::string key = Trim(line.substr(0, eq));
    if (h.fields.count(key))
      throw InputError(path + ": the MetaImage header gives " + key + " twice");
    h.fields[key] = Trim(line.substr(eq + 1));
    if (key == "ElementDataFile")
      break;
  }
  return h;
}

// The number of bytes the zlib (or gzip) stream at `offset` of `file`
// inflates to; the first `capacity` of them go to `dst` when it is not null.
// Throws if the stream is damaged or cut short.
uint64_t Inflate(
  const std::string& file, uint64_t offset, const std::string& where, uint8_t* dst = nullptr, uint64_t capacity = 0)
{
  std::ifstream in(file, std::ios::binary);
  if (!in.seekg((std::streamoff)offset))
    throw InputError(where + ": cannot read " + file);
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK)
    throw InputError(where + ": zlib failed to start"); // +32: zlib or gzip
  std::vector<unsigned char> input(1 << 16), output(1 << 18);
  uint64_t total = 0;
  int ret = Z_OK;
  while (ret != Z_STREAM_END)
  {
    if (zs.avail_in == 0)
    {
      in.read(reinterpret_cast<char*>(input.data()), (std::streamsize)input.size());
      if (in.gcount() == 0)
        break;
      zs.next_in = input.data();
      zs.avail_in = (uInt)in.gcount();
    }
    zs.next_out = output.data();
    zs.avail_out = (uInt)output.size();
    ret = inflate(&zs, Z_NO_FLUSH);
    if (ret != Z_OK && ret != Z_STREAM_END && ret != Z_BUF_ERROR)
      break;
    const uint64_t produced = output.size() - zs.avail_out;
    if (dst && total < capacity)
      std::copy_n(output.data(), std::min(produced, capacity - total), dst + total);
    total += produced;
  }
  inflateEnd(&zs);
  if (ret != Z_STREAM_END)
    throw InputError(where + ": compressed voxel data in " + fs::path(file).filename().string() +
      " is damaged or cut short (truncated?)");
  return total;
}

std::string Field(const MetaImageHeader& h, const char* key)
{
  auto it = h.fields.find(key);
  return it == h.fields.end() ? std::string() : it->second;
}

// Where the voxel data is: a file (the header itself for LOCAL) and the
// offset of the data in it.
struct MetaImageData
{
  std::string name; // ElementDataFile as written
  std::string file;
  uint64_t offset = 0;
  uint64_t fileSize = 0;
  bool compressed = false;
};

// The data of a single data file; nullopt for data split over several files
// (LIST, patterns) or at the end of a file of any size (HeaderSize -1), which
// are left to the reader.
std::optional<MetaImageData> LocateMetaImageData(const std::string& path, const MetaImageHeader& h)
{
  MetaImageData d;
  d.name = Field(h, "ElementDataFile");
  if (d.name.empty() || d.name == "LIST" || d.name.find('%') != std::string::npos)
    return std::nullopt;
  const long headerSize = Field(h, "HeaderSize").empty() ? 0 : std::atol(Field(h, "HeaderSize").c_str());
  if (headerSize < 0)
    return std::nullopt; // -1: data at the end of the file, any size
  const bool local = d.name == "LOCAL";
  d.file = local ? path : (fs::path(path).parent_path() / d.name).string();
  d.offset = (local ? h.size : 0) + (uint64_t)headerSize;
  std::error_code ec;
  d.fileSize = fs::file_size(d.file, ec);
  if (ec)
    throw InputError(path + ": cannot open its data file " + d.name);
  d.compressed = ToLower(Field(h, "CompressedData")) == "true";
  return d;
}

// Bytes per value of a MetaImage ElementType; 0 if unknown (the reader then
// names the problem).
int MetaElementSize(const std::string& type)
{
  static const std::pair<const char*, int> kTypes[] = { { "MET_CHAR", 1 }, { "MET_UCHAR", 1 }, { "MET_SHORT", 2 },
    { "MET_USHORT", 2 }, { "MET_INT", 4 }, { "MET_UINT", 4 }, { "MET_LONG", 4 }, { "MET_ULONG", 4 },
    { "MET_LONG_LONG", 8 }, { "MET_ULONG_LONG", 8 }, { "MET_FLOAT", 4 }, { "MET_DOUBLE", 8 } };
  for (const auto& [name, size] : kTypes)
    if (type == name)
      return size;
  return 0;
}

// `ElementDataFile = <pattern> [<min> [<max> [<step>]]]` names one file per
// slice: metaio formats each name with the pattern as a printf format and
// divides by the step, which it computes as (max - min) / slices when it is
// not given. So the pattern must hold exactly one integer conversion (%d,
// %03d, ...) and nothing else printf reads, and the step must be positive
// with max at least min: metaio counts up while the number is at most max,
// so a step of 0 divided by zero and a negative one never ended (fuzz
// findings: garbled ElementDataFile lines).
void CheckMetaImageFilePattern(const std::string& path, const std::string& value, double slices)
{
  std::istringstream in(value);
  std::vector<std::string> words;
  for (std::string w; in >> w;)
    words.push_back(w);
  const std::string problem = path + ": ElementDataFile '" + value + "': ";
  // Five words or more: a pattern with spaces, then min, max and step.
  size_t patternWords = words.size() >= 5 ? words.size() - 3 : 1;
  std::string pattern = words.empty() ? "" : words[0];
  for (size_t i = 1; i < patternWords; ++i)
    pattern += " " + words[i];
  CheckFileNamePattern(path, "ElementDataFile '" + value + "'", pattern);
  std::vector<double> numbers;
  for (size_t i = patternWords; i < words.size(); ++i)
  {
    char* end = nullptr;
    const double v = std::strtod(words[i].c_str(), &end);
    if (*end != '\0' || !(std::fabs(v) < 2147483647.0))
      throw InputError(problem + "<min> <max> <step> after the pattern must be integers");
    numbers.push_back(std::trunc(v));
  }
  // metaio's defaults: min 1; max min + slices - 1; step (max - min) / slices.
  const double min = numbers.size() >= 1 ? numbers[0] : 1;
  const double max = numbers.size() >= 2 ? numbers[1] : min + slices - 1;
  const double step = numbers.size() >= 3 ? numbers[2] : numbers.size() == 2 ? std::trunc((max - min) / slices) : 1;
  if (step <= 0 || max < min)
    throw InputError(problem + "the step (" + std::to_string((long long)step) + ") does not count up from " +
      std::to_string((long long)min) + " to " + std::to_string((long long)max));
}

// Before vtkMetaImageReader allocates: the voxels DimSize promises against
// the data that holds them (CheckDeclaredVoxelBytes), and the data file is
// there (metaio leaks its buffers when it is not: found by fuzzing).
void CheckMetaImageDeclaredSize(const std::string& path, const MetaImageHeader& h)
{
  // Every word of DimSize a positive integer: metaio reads "1-6" as a size
  // and allocated a negative number of bytes (a fuzz finding).
  const std::vector<int64_t> dims = PositiveIntegers(path, "DimSize", Field(h, "DimSize"));
  // metaio keeps up to 10 axes in fixed arrays and reads NDims numbers for
  // every per-axis field: an NDims of 2e17 kept it reading for minutes (a
  // fuzz finding), so NDims must be a whole number from 1 to 10. It reads
  // NDims sizes whatever the line holds, into the next line when it holds
  // fewer.
  const std::string ndims = Field(h, "NDims");
  if (!ndims.empty())
  {
    const std::optional<long long> n = IntegerWord(ndims);
    if (!n || *n < 1 || *n > 10)
      throw InputError(path + ": NDims must be a whole number from 1 to 10: " + ndims);
    if (dims.size() != (size_t)*n)
      throw InputError(path + ": DimSize gives " + std::to_string(dims.size()) + " sizes for NDims " + ndims);
  }
  // metaio reads an empty ElementDataFile as a stream it then sizes as -1
  // bytes (found by fuzzing).
  const std::string dataFile = Trim(Field(h, "ElementDataFile"));
  if (dataFile.empty())
    throw InputError(path + ": the MetaImage header names no ElementDataFile (LOCAL, or the data's file)");
  // metaio splits a LIST or pattern ElementDataFile into words in 80-byte
  // buffers and joins a pattern's words into the first: 80 characters or
  // more overflow its heap (a fuzz finding).
  const bool pattern = dataFile.find('%') != std::string::npos;
  if ((pattern || dataFile.rfind("LIST", 0) == 0) && dataFile.size() >= 80)
    throw InputError(path + ": ElementDataFile '" + dataFile.substr(0, 100) +
      "': a file list or pattern of 80 characters or more (metaio's limit)");
  if (pattern)
  {
    if (dims.empty())
      throw InputError(path + ": a file-name pattern needs DimSize");
    CheckMetaImageFilePattern(path, dataFile, (double)dims.back());
  }
  const std::optional<MetaImageData> d = LocateMetaImageData(path, h);
  // metaio allocates CompressedDataSize bytes before reading them.
  const std::string declared = Field(h, "CompressedDataSize");
  if (d && d->compressed && !declared.empty())
  {
    const double stated = std::atof(declared.c_str()),
                 available = d->fileSize > d->offset ? double(d->fileSize - d->offset) : 0.0;
    if (!(stated >= 0) || stated > available)
      throw InputError(path + ": CompressedDataSize says " + declared + " bytes but " +
        (d->name == "LOCAL" ? std::string("the file") : d->name) + " holds " + std::to_string((uint64_t)available) +
        " (truncated, or a corrupt header)");
  }
  const int size = MetaElementSize(Field(h, "ElementType"));
  if (!d || size == 0 || dims.empty())
    return;
  double count = std::max(1.0, std::atof(Field(h, "ElementNumberOfChannels").c_str()));
  for (int64_t n : dims)
    count *= (double)n;
  CheckDeclaredVoxelBytes(path, count * size, count, d->fileSize > d->offset ? double(d->fileSize - d->offset) : 0.0,
    d->compressed ? DataEncoding::Compressed : DataEncoding::Raw);
  // metaio loops forever on some damaged zlib streams (a fuzz finding), so
  // the stream is inflated here first (counting, not keeping): it must be
  // whole and hold every voxel. CheckMetaImageData then need not.
  if (d->compressed)
  {
    const uint64_t inflated = Inflate(d->file, d->offset, path); // throws when damaged or cut short
    if ((double)inflated < count * size)
      throw InputError(path + ": voxel data is " + std::to_string(inflated) + " bytes, expected " +
        std::to_string((uint64_t)(count * size)) + " (truncated?)");
  }
}

// Whether the header says its binary data is big endian (either key).
bool MetaImageBigEndian(const MetaImageHeader& h)
{
  return ToLower(Field(h, "BinaryDataByteOrderMSB") + Field(h, "ElementByteOrderMSB")).find("true") !=
    std::string::npos;
}

// metaio reports a short or damaged data file only on the console and
// returns what it read, so check that all `bytes` of voxel data (the
// reader's buffer `voxels`) are there.
void CheckMetaImageData(const std::string& path, const MetaImageHeader& h, uint8_t* voxels, uint64_t bytes,
  int valueSize, const VolumeLoadOptions& options)
{
  auto field = [&](const char* key) { return Field(h, key); };
  const std::optional<MetaImageData> d = LocateMetaImageData(path, h);
  if (!d)
    return;
  const std::string& dataName = d->name;
  const std::string& dataFile = d->file;
  const uint64_t offset = d->offset, fileSize = d->fileSize;
  const bool compressed = d->compressed;
  const long headerSize = field("HeaderSize").empty() ? 0 : std::atol(field("HeaderSize").c_str());
  // A wrong CompressedDataSize (the Whole Frog header said 260020 for a
  // 262087-byte stream) makes metaio, in VTK as in ITK, stop early and leave
  // garbage in the last slices: inflate the whole stream here instead.
  const std::string declared = field("CompressedDataSize");
  if (compressed && !declared.empty() && dataName != "LOCAL" && headerSize == 0 &&
    std::strtoull(declared.c_str(), nullptr, 10) != fileSize)
  {
    const uint64_t inflated = Inflate(dataFile, offset, path, voxels, bytes);
    if (inflated < bytes)
      throw InputError(path + ": voxel data is " + std::to_string(inflated) + " bytes, expected " +
        std::to_string(bytes) + " (truncated?)");
    if (MetaImageBigEndian(h) && valueSize > 1) // stored big endian; this machine is little endian
      for (uint64_t i = 0; i + valueSize <= bytes; i += valueSize)
        std::reverse(voxels + i, voxels + i + valueSize);
    Warn(options,
      path + ": CompressedDataSize says " + declared + " bytes but " + dataName + " holds " + std::to_string(fileSize) +
        "; the header is wrong (readers that trust it stop early and " +
        "leave garbage), so the whole stream was inflated and checked");
    return;
  }
  if (compressed)
    return; // inflated and counted before the read (CheckMetaImageDeclaredSize)
  const uint64_t available = fileSize > offset ? fileSize - offset : 0;
  if (available < bytes)
    throw InputError(path + ": voxel data is " + std::to_string(available) + " bytes, expected " +
      std::to_string(bytes) + " (truncated?)");
}

// The voxel type of a MetaImage ElementType the tracer samples as it is;
// nullopt for the others (read and converted through vtkMetaImageReader).
std::optional<VoxelType> MetaNativeType(const std::string& type)
{
  if (type == "MET_UCHAR")
    return VoxelType::UInt8;
  if (type == "MET_SHORT")
    return VoxelType::Int16;
  if (type == "MET_USHORT")
    return VoxelType::UInt16;
  if (type == "MET_FLOAT")
    return VoxelType::Float32;
  return std::nullopt;
}

// The first of `keys` present with exactly `n` numbers.
std::optional<std::vector<double>> MetaNumbers(
  const std::map<std::string, std::string>& fields, std::initializer_list<const char*> keys, size_t n)
{
  for (const char* key : keys)
  {
    auto it = fields.find(key);
    if (it == fields.end())
      continue;
    std::vector<double> v = ParseNumbers(it->second);
    if (v.size() == n)
      return v;
  }
  return std::nullopt;
}

} // namespace

void LoadMetaImage(const std::string& path, HostVolume& out, const VolumeLoadOptions& options)
{
  const MetaImageHeader header = ReadMetaImageHeader(path);
  const auto& fields = header.fields;
  if (fields.find("ObjectType") == fields.end() && fields.find("NDims") == fields.end())
    throw InputError(path + ": not a MetaImage header (no ObjectType or NDims)");
  CheckMetaImageDeclaredSize(path, header);
  Vec3d origin{ 0, 0, 0 }, spacing{ 1, 1, 1 }; // metaio's defaults
  Mat3d direction = kIdentity3;

  // Uncompressed 3D voxels of a native type in one file: read in place
  // (ReadRawVoxels), in the file's order, as vtkMetaImageReader keeps it.
  const std::optional<MetaImageData> data = LocateMetaImageData(path, header);
  const std::optional<VoxelType> native = MetaNativeType(Field(header, "ElementType"));
  const std::vector<int64_t> dims = PositiveIntegers(path, "DimSize", Field(header, "DimSize"));
  const std::string channels = Field(header, "ElementNumberOfChannels");
  if (data && !data->compressed && native && dims.size() == 3 && (channels.empty() || channels == "1"))
  {
    out.dims = { (int)dims[0], (int)dims[1], (int)dims[2] };
    RawVoxels raw;
    raw.path = path;
    raw.file = data->file;
    raw.offset = data->offset;
    raw.count = out.VoxelCount();
    raw.type = *native;
    raw.bigEndian = MetaImageBigEndian(header);
    ReadRawVoxels(raw, out, options);
  }
  else
  {
    vtkNew<vtkMetaImageReader> reader;
    reader->SetFileName(path.c_str());
    vtkImageData* image = RunReader(reader, path, options.progress);
    vtkDataArray* a = VoxelArray(image, path);
    CheckMetaImageData(path, header, static_cast<uint8_t*>(a->GetVoidPointer(0)),
      (uint64_t)a->GetNumberOfValues() * (uint64_t)a->GetDataTypeSize(), a->GetDataTypeSize(), options);
    StoreImageVoxels(image, path, Rescale{}, out);
    // 2D images (NDims 2) keep VTK's origin and spacing.
    const double* o = image->GetOrigin();
    const double* s = image->GetSpacing();
    origin = { o[0], o[1], o[2] };
    spacing = { s[0], s[1], s[2] };
  }
  if (auto v = MetaNumbers(fields, { "Offset", "Position", "Origin" }, 3))
    origin = { (*v)[0], (*v)[1], (*v)[2] };
  if (auto v = MetaNumbers(fields, { "ElementSpacing", "ElementSize" }, 3))
    spacing = { (*v)[0], (*v)[1], (*v)[2] };
  if (auto v = MetaNumbers(fields, { "TransformMatrix", "Rotation", "Orientation" }, 9))
    for (int axis = 0; axis < 3; ++axis)
      for (int r = 0; r < 3; ++r)
        direction[3 * r + axis] = (*v)[3 * axis + r];
  out.indexToWorld = IndexToWorld(origin, spacing, direction);
}

} // namespace mmrtm
