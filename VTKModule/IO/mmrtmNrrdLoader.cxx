// NRRD volumes (.nrrd, .nhdr): raw voxels of a native type are read straight
// into the volume (ReadRawVoxels); vtkNrrdReader reads the others (gzip,
// text, split data, converted types). The geometry and the axis layout come
// from this file's own parse of the NRRD header.
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkNrrdReader.h>

namespace mmrtm
{

// vtkNrrdReader reads the voxels, but its geometry is not usable: it ignores
// the direction of `space directions` (keeping only their lengths), leaves
// `space origin` in the file's space, reverses the rows of raw-encoded files
// in left-handed spaces (LAS), and takes a fastest axis of 9 or fewer samples
// for vector components. So the geometry and the axis layout come from our
// own parse of the header, and the voxels are put back in file order.

namespace
{

struct NrrdHeader
{
  int dimension = 0;
  std::vector<int64_t> sizes;
  std::string space;    // lower-case, "" if absent
  std::string encoding; // lower-case, "raw" if absent
  bool hasSpaceDirections = false;
  std::vector<std::optional<Vec3d>> directions; // per axis; nullopt = "none"
  std::optional<Vec3d> origin;
  std::vector<double> spacings;        // per axis, from the older `spacings` field
  int typeSize = 0;                    // bytes per value of `type`; 0 if unknown
  std::optional<VoxelType> nativeType; // `type` when the tracer samples it as it is
  bool bigEndian = false;              // `endian: big`
  bool skips = false;                  // a `line skip` or `byte skip` other than 0
  std::string dataFile;                // `data file` as written; "" when the data is attached
  // How vtkNrrdReader reads `data file`: a first word "LIST" exactly is a
  // list of files; four words or more are a name pattern (so
  // "LISTslice%d.raw 1 2 0" is a pattern: a fuzz finding); fewer are one
  // file name.
  bool dataFileList = false, dataFilePattern = false;
  int64_t headerBytes = 0; // the header and its blank line
  // How many sizes vtkNrrdReader reads: its axis count when it meets
  // `sizes`, which `space` (3) and `space dimension` reset after
  // `dimension`. -1 when there is no `sizes`.
  int vtkSizeCount = -1;
  bool vtkFirstSpacingZero = false; // its guess of a vector axis also looks at this
};

// A NRRD `type` (teem's names and aliases): its bytes per value and the
// type of the stored values.
struct NrrdType
{
  int size;
  SourceType source;
};

// nullopt for a name teem does not know (vtkNrrdReader then names the problem).
std::optional<NrrdType> FindNrrdType(const std::string& type)
{
  using S = SourceType;
  static const std::pair<const char*, NrrdType> kTypes[] = { { "uchar", { 1, S::UInt8 } },
    { "unsigned char", { 1, S::UInt8 } }, { "uint8", { 1, S::UInt8 } }, { "uint8_t", { 1, S::UInt8 } },
    { "signed char", { 1, S::Int8 } }, { "int8", { 1, S::Int8 } }, { "int8_t", { 1, S::Int8 } },
    { "char", { 1, S::Int8 } }, { "short", { 2, S::Int16 } }, { "short int", { 2, S::Int16 } },
    { "signed short", { 2, S::Int16 } }, { "signed short int", { 2, S::Int16 } }, { "int16", { 2, S::Int16 } },
    { "int16_t", { 2, S::Int16 } }, { "ushort", { 2, S::UInt16 } }, { "unsigned short", { 2, S::UInt16 } },
    { "unsigned short int", { 2, S::UInt16 } }, { "uint16", { 2, S::UInt16 } }, { "uint16_t", { 2, S::UInt16 } },
    { "int", { 4, S::Int32 } }, { "signed int", { 4, S::Int32 } }, { "int32", { 4, S::Int32 } },
    { "int32_t", { 4, S::Int32 } }, { "uint", { 4, S::UInt32 } }, { "unsigned int", { 4, S::UInt32 } },
    { "uint32", { 4, S::UInt32 } }, { "uint32_t", { 4, S::UInt32 } }, { "longlong", { 8, S::Int64 } },
    { "long long", { 8, S::Int64 } }, { "long long int", { 8, S::Int64 } }, { "signed long long", { 8, S::Int64 } },
    { "signed long long int", { 8, S::Int64 } }, { "int64", { 8, S::Int64 } }, { "int64_t", { 8, S::Int64 } },
    { "ulonglong", { 8, S::UInt64 } }, { "unsigned long long", { 8, S::UInt64 } },
    { "unsigned long long int", { 8, S::UInt64 } }, { "uint64", { 8, S::UInt64 } }, { "uint64_t", { 8, S::UInt64 } },
    { "float", { 4, S::Float32 } }, { "double", { 8, S::Float64 } } };
  for (const auto& [name, t] : kTypes)
    if (type == name)
      return t;
  return std::nullopt;
}

// "(a,b,c)" -> vector; "none" -> nullopt. Throws on anything else.
std::optional<Vec3d> ParseNrrdVector(const std::string& token, const std::string& path)
{
  if (token == "none")
    return std::nullopt;
  std::string inner = token;
  if (inner.size() < 2 || inner.front() != '(' || inner.back() != ')')
    throw InputError(path + ": bad NRRD vector '" + token + "'");
  inner = inner.substr(1, inner.size() - 2);
  std::replace(inner.begin(), inner.end(), ',', ' ');
  const std::vector<double> v = ParseNumbers(inner);
  if (v.size() != 3)
    throw InputError(path + ": NRRD vector '" + token + "' does not have 3 components");
  return Vec3d{ v[0], v[1], v[2] };
}

// Splits "(1,0,0) (0, 1, 0) none" into vector tokens, allowing spaces inside parentheses.
std::vector<std::string> SplitNrrdVectors(const std::string& text)
{
  std::vector<std::string> tokens;
  std::string current;
  int depth = 0;
  for (char c : text)
  {
    if (c == '(')
      ++depth;
    if (c == ')')
      --depth;
    if (std::isspace((unsigned char)c) && depth == 0)
    {
      if (!current.empty())
        tokens.push_back(current);
      current.clear();
    }
    else if (!std::isspace((unsigned char)c))
    {
      current += c;
    }
  }
  if (!current.empty())
    tokens.push_back(current);
  return tokens;
}

// Reads the header lines: up to the first blank line (a detached .nhdr header
// is the whole file); `bytes` receives their length with the blank line.
// Stops after 1 MiB so a file without a blank line is not scanned as text to
// its end. A header is text: a control character (binary data where a field
// should be) is an error here, before vtkNrrdReader sees it (a NUL in
// `data file` made it grow a string array past a gigabyte).
std::vector<std::string> ReadNrrdHeaderLines(const std::string& path, int64_t* bytes)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path + ": cannot open");
  std::vector<std::string> lines;
  std::string line;
  *bytes = 0;
  bool ended = false; // by a blank line
  while (*bytes < (1 << 20) && std::getline(in, line))
  {
    // vtkNrrdReader reads a last line without a line end again and again
    // (found by fuzzing): such a header is cut short, and an error here.
    if (in.eof())
      throw InputError(path + ": the NRRD header's last line has no line end (truncated?)");
    *bytes += (int64_t)line.size() + 1;
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    if (line.empty())
    {
      ended = true;
      break;
    }
    if (lines.empty() && line.rfind("NRRD", 0) != 0)
      throw InputError(path + ": not a NRRD file (no NRRD magic)");
    for (unsigned char c : line)
      if (c < 0x20 && c != '\t')
        throw InputError(path + ": line " + std::to_string(lines.size() + 1) +
          " of the NRRD header holds a control character (binary data in the header?)");
    lines.push_back(line);
  }
  if (lines.empty())
    throw InputError(path + ": not a NRRD file (no NRRD magic)");
  const bool detached = std::any_of(lines.begin(), lines.end(),
    [](const std::string& l) { return l.rfind("data file:", 0) == 0 || l.rfind("datafile:", 0) == 0; });
  if (!ended && !detached)
    throw InputError(path + ": no blank line ends the NRRD header, so there is no attached data (truncated?)");
  return lines;
}

NrrdHeader ParseNrrdHeader(const std::string& path)
{
  NrrdHeader h;
  const std::vector<std::string> lines = ReadNrrdHeaderLines(path, &h.headerBytes);
  std::set<std::string> seen;
  int vtkAxes = 0; // vtkNrrdReader's axis count as it reads the lines
  for (size_t i = 1; i < lines.size(); ++i)
  {
    const std::string& line = lines[i];
    if (line[0] == '#')
      continue;
    const size_t colon = line.find(": ");
    if (colon == std::string::npos)
      continue; // "key:=value" pairs and junk carry no geometry
    // The field as vtkNrrdReader matches it: exactly, not trimmed.
    const std::string field = line.substr(0, colon), value = Trim(line.substr(colon + 2));
    // The format allows each field once; vtkNrrdReader acts on every copy
    // as it reads it (a second `data file` line was formatted unchecked: a
    // fuzz finding), so a repeated field is an error.
    if (!seen.insert(field == "datafile" ? "data file" : field).second)
      throw InputError(path + ": the NRRD header gives '" + field + "' twice");
    // The format puts `dimension` before every per-axis field; vtkNrrdReader
    // crashes on `sizes` before it (a fuzz finding).
    static const char* kPerAxis[] = { "sizes", "spacings", "thicknesses", "axis mins", "axismins", "axis maxs",
      "axismaxs", "centers", "centerings", "labels", "units", "kinds", "space directions" };
    if (!seen.count("dimension") && std::find(std::begin(kPerAxis), std::end(kPerAxis), field) != std::end(kPerAxis))
      throw InputError(
        path + ": the NRRD header gives '" + field + "' before 'dimension' (the format wants dimension first)");
    if (field == "dimension")
    {
      h.dimension = std::atoi(value.c_str());
      vtkAxes = h.dimension;
    }
    else if (field == "space dimension")
    {
      vtkAxes = std::atoi(value.c_str());
    }
    else if (field == "sizes")
    {
      h.vtkSizeCount = vtkAxes;
      // Every word a positive integer: vtkNrrdReader reads "2t" as a size
      // too and then reads voxels into a null buffer (a fuzz finding).
      h.sizes = PositiveIntegers(path, "NRRD 'sizes'", value);
    }
    else if (field == "space")
    {
      h.space = ToLower(value);
      vtkAxes = 3;
    }
    else if (field == "encoding")
    {
      h.encoding = ToLower(value);
    }
    else if (field == "type")
    {
      if (const std::optional<NrrdType> t = FindNrrdType(ToLower(value)))
      {
        h.typeSize = t->size;
        h.nativeType = NativeVoxelType(t->source);
      }
    }
    else if (field == "endian")
    {
      h.bigEndian = ToLower(value) == "big";
    }
    else if (field == "byte skip" || field == "byteskip" || field == "line skip" || field == "lineskip")
    {
      h.skips = value != "0";
    }
    else if (field == "data file" || field == "datafile")
    {
      h.dataFile = value;
      std::istringstream in(value);
      const std::vector<std::string> words{ std::istream_iterator<std::string>(in), {} };
      h.dataFileList = !words.empty() && words[0] == "LIST";
      h.dataFilePattern = !h.dataFileList && words.size() >= 4;
    }
    else if (field == "space directions")
    {
      h.hasSpaceDirections = true;
      for (const std::string& token : SplitNrrdVectors(value))
        h.directions.push_back(ParseNrrdVector(token, path));
      h.vtkFirstSpacingZero =
        !h.directions.empty() && (!h.directions[0] || Dot(*h.directions[0], *h.directions[0]) == 0.0);
    }
    else if (field == "space origin")
    {
      h.origin = ParseNrrdVector(value, path);
    }
    else if (field == "spacings")
    {
      std::istringstream in(value);
      std::string token;
      while (in >> token)
        h.spacings.push_back(ToLower(token) == "nan" ? std::nan("") : std::atof(token.c_str()));
      h.vtkFirstSpacingZero = !h.spacings.empty() && h.spacings[0] == 0.0;
    }
  }
  if (h.encoding.empty())
    h.encoding = "raw";
  // vtkNrrdReader reads voxels of no type into a null buffer (a fuzz finding).
  if (h.typeSize == 0)
    throw InputError(path + ": the NRRD header has no 'type' of a known kind");
  if (h.dimension <= 0 || (int)h.sizes.size() != h.dimension)
    throw InputError(path + ": NRRD header has no valid 'dimension' and 'sizes'");
  // vtkNrrdReader sizes its axes by `space` or `space dimension` when they
  // come between `dimension` and `sizes`: with none left, or with more than
  // the file has, it indexed an empty list (a fuzz finding) or allocated
  // what `space dimension` promised.
  if (h.vtkSizeCount < 1 || h.vtkSizeCount > h.dimension)
    throw InputError(path + ": the NRRD header's 'space dimension' or 'space' before 'sizes' gives " +
      std::to_string(h.vtkSizeCount) + " axes for a dimension of " + std::to_string(h.dimension));
  // The axes vtkNrrdReader reads from the file: it takes a first axis of 9
  // samples or fewer (or of no spacing), or a fourth axis, for vector
  // components, and one axis for the files when the data is split. Its
  // raw and text reads open the file only for 2 or 3 axes, and read
  // through a null stream otherwise (fuzz findings: one axis; two axes, the
  // first of 2 samples).
  const bool vectorAxis = h.vtkSizeCount > 3 || h.sizes[0] <= 9 || h.vtkFirstSpacingZero;
  const int fileAxes = h.vtkSizeCount - (vectorAxis ? 1 : 0);
  const bool split = h.dataFileList || h.dataFilePattern;
  if (split ? fileAxes != 3 : (fileAxes < 2 || fileAxes > 3))
    throw InputError(path + ": vtkNrrdReader would read " + std::to_string(split ? fileAxes - 1 : fileAxes) +
      " image axes from " + (split ? "each of its data files (it reads 2)" : "this NRRD file (it reads 2 or 3)") +
      (vectorAxis ? ", taking the first axis for vector components" : ""));
  if (h.hasSpaceDirections && (int)h.directions.size() != h.dimension)
    throw InputError(path + ": NRRD 'space directions' has " + std::to_string(h.directions.size()) + " entries for " +
      std::to_string(h.dimension) + " axes");
  return h;
}

// `data file: <format> <min> <max> <step> [<subdim>]` names its files by a
// counter: all four must be integers, the step not 0 and towards `max`, and
// there can be no more files than samples. vtkNrrdReader takes any words
// as numbers and, with a step of 0, adds names until memory runs out (a
// fuzz finding: a garbled `data file` line).
void CheckNrrdFilePattern(const NrrdHeader& h, const std::string& path)
{
  std::istringstream in(h.dataFile);
  std::string format, words[4];
  in >> format;
  int count = 0;
  while (count < 4 && in >> words[count])
    ++count;
  // Within int: vtkNrrdReader reads them as int (a step of 8.9e72 became a
  // garbage step that added names until memory ran out: a fuzz finding).
  auto integer = [](const std::string& w, long long* v)
  {
    const std::optional<long long> parsed = IntegerWord(w);
    if (parsed)
      *v = *parsed;
    return parsed.has_value();
  };
  long long min = 0, max = 0, step = 0, subdim = 0;
  const std::string problem = path + ": NRRD 'data file: " + h.dataFile + "': ";
  CheckFileNamePattern(path, "NRRD 'data file: " + h.dataFile + "'", format);
  if (count < 3 || !integer(words[0], &min) || !integer(words[1], &max) || !integer(words[2], &step))
    throw InputError(problem + "a file-name pattern needs integers <min> <max> <step> after it");
  if (count == 4 && (!integer(words[3], &subdim) || subdim < 1 || subdim > h.dimension))
    throw InputError(problem + "<subdim> must be an axis count from 1 to the dimension");
  const double files = ((double)max - (double)min) / (double)step + 1; // in double: no overflow
  if (step == 0 || files < 1)
    throw InputError(problem + "the step does not go from <min> to <max>");
  double samples = 1;
  for (int64_t n : h.sizes)
    samples *= (double)n;
  if (files > samples)
    throw InputError(problem + "more files than the volume has samples");
}

// The voxels the header promises against the bytes that hold them
// (CheckDeclaredVoxelBytes), before vtkNrrdReader allocates for them. Data
// split over several files (`data file: LIST` or a name pattern) is left to
// the reader, once a pattern's counter is checked.
void CheckNrrdDataSize(const NrrdHeader& h, const std::string& path)
{
  if (h.dataFilePattern)
    CheckNrrdFilePattern(h, path);
  if (h.dataFileList || h.dataFilePattern)
    return;
  double count = 1;
  for (int64_t n : h.sizes)
    count *= (double)n;
  std::error_code ec;
  double fileBytes;
  if (h.dataFile.empty())
  {
    fileBytes = (double)std::filesystem::file_size(path, ec) - (double)h.headerBytes;
  }
  else
  {
    const std::filesystem::path data = std::filesystem::path(path).parent_path() / h.dataFile;
    fileBytes = (double)std::filesystem::file_size(data, ec);
    if (ec)
      throw InputError(path + ": its data file '" + h.dataFile + "' cannot be read (" + ec.message() + ")");
  }
  if (ec)
    throw InputError(path + ": cannot read its size (" + ec.message() + ")");
  DataEncoding encoding = DataEncoding::Compressed; // gzip, bzip2
  if (h.encoding == "raw" || h.encoding == "hex")
    encoding = DataEncoding::Raw; // hex: two characters a byte
  if (h.encoding == "ascii" || h.encoding == "text" || h.encoding == "txt")
    encoding = DataEncoding::Text;
  CheckDeclaredVoxelBytes(path, count * h.typeSize, count, std::max(0.0, fileBytes), encoding, h.dataFile);
}

// Per-axis signs that take coordinates of a NRRD space to LPS. Spaces
// without anatomy (scanner-xyz, 3D-right-handed, ...) are taken as they are.
Vec3d NrrdSpaceToLps(const std::string& space)
{
  if (space == "right-anterior-superior" || space == "ras")
    return { -1, -1, 1 };
  if (space == "left-anterior-superior" || space == "las")
    return { 1, -1, 1 };
  return { 1, 1, 1 };
}

// The axes that are space, not vector components: those with a direction
// when `space directions` is given; else all of them, except that a 4-axis
// file's fastest axis is the components axis (vtkNrrdReader's assumption).
std::vector<int> NrrdSpatialAxes(const NrrdHeader& h)
{
  std::vector<int> axes;
  for (int a = 0; a < h.dimension; ++a)
  {
    if (h.hasSpaceDirections ? h.directions[a].has_value() : !(h.dimension == 4 && a == 0))
      axes.push_back(a);
  }
  return axes;
}

// Index -> LPS world from `space directions` and `space origin` (or the
// older `spacings`, with an identity direction), for the spatial axes.
Affine3 NrrdIndexToWorld(const NrrdHeader& h, const std::vector<int>& spatial, const std::string& path)
{
  const Vec3d toLps = NrrdSpaceToLps(h.space);
  Vec3d origin{ 0, 0, 0 }, spacing{ 1, 1, 1 };
  Mat3d direction = kIdentity3;
  if (h.origin)
    for (int r = 0; r < 3; ++r)
      origin[r] = (*h.origin)[r] * toLps[r];
  for (int c = 0; c < (int)spatial.size(); ++c)
  {
    const int axis = spatial[c];
    if (h.hasSpaceDirections)
    {
      const Vec3d& v = *h.directions[axis];
      spacing[c] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (!(spacing[c] > 0) || !std::isfinite(spacing[c]))
        throw InputError(path + ": NRRD space direction of axis " + std::to_string(axis) + " is zero or not finite");
      for (int r = 0; r < 3; ++r)
        direction[3 * r + c] = v[r] * toLps[r] / spacing[c];
    }
    else if (axis < (int)h.spacings.size() && std::isfinite(h.spacings[axis]) && h.spacings[axis] != 0)
    {
      spacing[c] = h.spacings[axis];
    }
  }
  // A 2D image's missing k axis: the plane normal, so the matrix stays invertible.
  if (spatial.size() == 2 && h.hasSpaceDirections)
  {
    const Vec3d n =
      Cross(Vec3d{ direction[0], direction[3], direction[6] }, Vec3d{ direction[1], direction[4], direction[7] });
    const double length = std::sqrt(Dot(n, n));
    for (int r = 0; r < 3; ++r)
      direction[3 * r + 2] = length > 0 ? n[r] / length : kIdentity3[3 * r + 2];
  }
  return IndexToWorld(origin, spacing, direction);
}

} // namespace

void LoadNrrd(const std::string& path, HostVolume& out, const VolumeLoadOptions& options)
{
  const NrrdHeader h = ParseNrrdHeader(path);
  const std::vector<int> spatial = NrrdSpatialAxes(h);
  int64_t components = 1;
  for (int a = 0; a < h.dimension; ++a)
    if (std::find(spatial.begin(), spatial.end(), a) == spatial.end())
      components *= h.sizes[a];
  if (components != 1)
    ThrowComponents(path, components);
  if (spatial.empty() || spatial.size() > 3)
    throw InputError(
      path + ": a NRRD volume needs 1 to 3 spatial axes, this one has " + std::to_string(spatial.size()));

  CheckNrrdDataSize(h, path);
  for (int i = 0; i < 3; ++i)
    out.dims[i] = i < (int)spatial.size() ? (int)h.sizes[spatial[i]] : 1;
  out.indexToWorld = NrrdIndexToWorld(h, spatial, path);

  // Raw voxels of a native type in one file: read in place, at the speed
  // of the disk (or the page cache), in the file's own order.
  if (h.encoding == "raw" && h.nativeType && !h.skips && !h.dataFileList && !h.dataFilePattern)
  {
    RawVoxels raw;
    raw.path = path;
    raw.file = h.dataFile.empty() ? path : (std::filesystem::path(path).parent_path() / h.dataFile).string();
    raw.offset = h.dataFile.empty() ? (uint64_t)h.headerBytes : 0;
    raw.count = out.VoxelCount();
    raw.type = *h.nativeType;
    raw.bigEndian = h.bigEndian;
    ReadRawVoxels(raw, out, options);
    return;
  }

  vtkNew<vtkNrrdReader> reader;
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path, options.progress);
  vtkDataArray* a = VoxelArray(image, path);

  // The axis layout comes from our header; the buffer is the same whatever
  // vtkNrrdReader made of the axes (x fastest either way).
  const int64_t values = (int64_t)a->GetNumberOfTuples() * a->GetNumberOfComponents();
  if (values != out.VoxelCount())
    throw InputError(path + ": holds " + std::to_string(values) + " voxels, expected " +
      std::to_string(out.VoxelCount()) + " (truncated or corrupt?)");
  StoreArrayVoxels(a, out.VoxelCount(), Rescale{}, ArrayHolder::Loader, out, path);
  // vtkImageReader2 (raw encoding only) stores the rows of each slice bottom
  // up when FileLowerLeft is off; undo that in the reader's own row layout,
  // which may differ from ours when it took the x axis for components.
  if (!reader->GetFileLowerLeft() && h.encoding == "raw")
  {
    const int* vtkDims = image->GetDimensions();
    ReverseRuns(out, (int64_t)vtkDims[0] * a->GetNumberOfComponents(), vtkDims[1]);
  }
}

} // namespace mmrtm
