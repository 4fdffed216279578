// Volume loader: one entry point, one function per format. See the header for
// the contract. The file is laid out in sections:
//   1. small helpers (strings, files, errors)
//   2. voxel conversion (native types, rescale, axis flips)
//   3. VTK glue (reader errors, scalar arrays, image geometry)
//   4. one loader per format: NRRD, NIfTI, MetaImage, VTI, legacy VTK, DICOM, InVesalius
//   5. LoadVolume, which dispatches on the path
#include "mmrtmVolumeLoader.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include <vtkCommand.h>
#include <vtkDICOMImageReader.h>
#include <vtkDataArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkMetaImageReader.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNew.h>
#include <vtkNrrdReader.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStructuredPointsReader.h>
#include <vtkType.h>
#include <vtkXMLImageDataReader.h>

namespace fs = std::filesystem;

namespace mmrtm {
namespace {

using Vec3d = std::array<double, 3>;
using Mat3d = std::array<double, 9>;  // row-major; column c is the direction of index axis c

constexpr Mat3d kIdentity3 = {1, 0, 0, 0, 1, 0, 0, 0, 1};

// ---------------------------------------------------------------------------
// 1. Small helpers
// ---------------------------------------------------------------------------

std::string ToLower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return (char)std::tolower(c); });
  return s;
}

std::string Trim(const std::string& s) {
  const char* space = " \t\r\n\f\v";
  size_t b = s.find_first_not_of(space);
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(space) - b + 1);
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Whitespace-separated numbers; stops at the first token that is not one.
std::vector<double> ParseNumbers(const std::string& text) {
  std::vector<double> out;
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    char* end = nullptr;
    double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') break;
    out.push_back(v);
  }
  return out;
}

Vec3d Cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

[[noreturn]] void ThrowComponents(const std::string& path, int64_t components) {
  throw InputError(path + ": has " + std::to_string(components) +
                   " components; a single-component volume is needed");
}

// The extension that selects the format, lower-case, with ".nii.gz" kept whole.
std::string VolumeExtension(const std::string& path) {
  const std::string file = ToLower(fs::path(path).filename().string());
  if (EndsWith(file, ".nii.gz")) return ".nii.gz";
  return fs::path(file).extension().string();
}

// ---------------------------------------------------------------------------
// 2. Voxel conversion
// ---------------------------------------------------------------------------

// Voxel types as files store them, before the choice of a HostVolume type.
enum class SourceType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

// Calls f with the data pointer cast to the C++ type of `type`.
template <typename F>
void WithTypedPointer(SourceType type, const void* data, F&& f) {
  switch (type) {
    case SourceType::Int8: f(static_cast<const int8_t*>(data)); break;
    case SourceType::UInt8: f(static_cast<const uint8_t*>(data)); break;
    case SourceType::Int16: f(static_cast<const int16_t*>(data)); break;
    case SourceType::UInt16: f(static_cast<const uint16_t*>(data)); break;
    case SourceType::Int32: f(static_cast<const int32_t*>(data)); break;
    case SourceType::UInt32: f(static_cast<const uint32_t*>(data)); break;
    case SourceType::Int64: f(static_cast<const int64_t*>(data)); break;
    case SourceType::UInt64: f(static_cast<const uint64_t*>(data)); break;
    case SourceType::Float32: f(static_cast<const float*>(data)); break;
    case SourceType::Float64: f(static_cast<const double*>(data)); break;
  }
}

// The types the tracer stores as they are (DESIGN.md rule 3).
std::optional<VoxelType> NativeVoxelType(SourceType t) {
  switch (t) {
    case SourceType::UInt8: return VoxelType::UInt8;
    case SourceType::Int16: return VoxelType::Int16;
    case SourceType::UInt16: return VoxelType::UInt16;
    case SourceType::Float32: return VoxelType::Float32;
    default: return std::nullopt;
  }
}

// value = stored * slope + intercept (NIfTI scl_*, DICOM rescale).
struct Rescale {
  double slope = 1.0, intercept = 0.0;
  bool IsIdentity() const { return slope == 1.0 && intercept == 0.0; }
};

struct ValueStats {
  bool allIntegers = true;
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
};

template <typename T>
ValueStats ScanValues(const T* p, int64_t n, Rescale r) {
  ValueStats s;
  for (int64_t i = 0; i < n; ++i) {
    const double v = (double)p[i] * r.slope + r.intercept;
    if (!(std::isfinite(v) && v == std::floor(v))) s.allIntegers = false;  // NaN fails too
    s.lo = std::min(s.lo, v);
    s.hi = std::max(s.hi, v);
  }
  return s;
}

// The smallest integer type that holds every value exactly, else float32.
// int16 is preferred over uint16 when both fit: CT and most medical data are signed.
VoxelType SmallestExactType(const ValueStats& s) {
  if (!s.allIntegers) return VoxelType::Float32;
  if (s.lo >= 0 && s.hi <= 255) return VoxelType::UInt8;
  if (s.lo >= -32768 && s.hi <= 32767) return VoxelType::Int16;
  if (s.lo >= 0 && s.hi <= 65535) return VoxelType::UInt16;
  return VoxelType::Float32;
}

template <typename Out, typename In>
void ConvertValues(const In* in, int64_t n, Rescale r, uint8_t* outBytes) {
  Out* out = reinterpret_cast<Out*>(outBytes);
  for (int64_t i = 0; i < n; ++i) out[i] = static_cast<Out>((double)in[i] * r.slope + r.intercept);
}

// Stores `count` voxels of `type` into `out` (type and voxels), applying the
// rescale and choosing the voxel type by the rules in the header.
void StoreVoxels(const void* data, SourceType type, int64_t count, Rescale rescale, HostVolume& out) {
  if (const auto native = NativeVoxelType(type); native && rescale.IsIdentity()) {
    out.type = *native;
    const auto* bytes = static_cast<const uint8_t*>(data);
    out.voxels.assign(bytes, bytes + count * VoxelTypeSize(*native));
    return;
  }
  // float32 stays float32 after a rescale; every other type may become an
  // integer type when its (rescaled) values allow it.
  VoxelType target = VoxelType::Float32;
  if (type != SourceType::Float32)
    WithTypedPointer(type, data, [&](auto* p) { target = SmallestExactType(ScanValues(p, count, rescale)); });
  out.type = target;
  out.voxels.resize((size_t)(count * VoxelTypeSize(target)));
  WithTypedPointer(type, data, [&](auto* p) {
    switch (target) {
      case VoxelType::UInt8: ConvertValues<uint8_t>(p, count, rescale, out.voxels.data()); break;
      case VoxelType::Int16: ConvertValues<int16_t>(p, count, rescale, out.voxels.data()); break;
      case VoxelType::UInt16: ConvertValues<uint16_t>(p, count, rescale, out.voxels.data()); break;
      case VoxelType::Float32: ConvertValues<float>(p, count, rescale, out.voxels.data()); break;
    }
  });
}

// Reverses, in place, the order of the runs of `runVoxels` voxels within each
// block of `runsPerBlock` runs. With runs of one row (nx voxels) and blocks of
// one slice this flips y; with runs of one slice and one block it flips z.
void ReverseRuns(HostVolume& v, int64_t runVoxels, int64_t runsPerBlock) {
  const size_t run = (size_t)runVoxels * VoxelTypeSize(v.type), block = run * (size_t)runsPerBlock;
  if (run == 0 || block == 0) return;
  for (size_t b = 0; b + block <= v.voxels.size(); b += block)
    for (int64_t lo = 0, hi = runsPerBlock - 1; lo < hi; ++lo, --hi)
      std::swap_ranges(v.voxels.begin() + b + lo * run, v.voxels.begin() + b + (lo + 1) * run,
                       v.voxels.begin() + b + hi * run);
}

// ---------------------------------------------------------------------------
// 3. VTK glue
// ---------------------------------------------------------------------------

// VTK error text looks like "ERROR: In file.cxx, line N\nvtkFoo (0x...): what\n\n";
// keep "what", which is the part a user can act on.
std::string CleanVtkMessage(const std::string& raw) {
  std::string msg = raw;
  const size_t newline = msg.find('\n');
  if (msg.rfind("ERROR:", 0) == 0 || msg.rfind("Warning:", 0) == 0 || msg.rfind("Generic Warning:", 0) == 0) {
    if (newline != std::string::npos) msg = msg.substr(newline + 1);
    const size_t tag = msg.find("): ");
    if (tag != std::string::npos) msg = msg.substr(tag + 3);
  }
  // Some messages quote the file's bytes: keep them printable and short.
  for (char& c : msg)
    if (!std::isprint((unsigned char)c) && c != '\n') c = '?';
  msg = Trim(msg);
  if (msg.size() > 300) msg = msg.substr(0, 300) + "...";
  return msg;
}

// vtkErrorCode's own names live in VTK::CommonMisc, which the project does
// not link; these are the codes readers set.
std::string DescribeVtkErrorCode(unsigned long code) {
  switch (code) {
    case vtkErrorCode::FileNotFoundError: return "file not found";
    case vtkErrorCode::CannotOpenFileError: return "cannot open the file";
    case vtkErrorCode::UnrecognizedFileTypeError: return "unrecognized file type";
    case vtkErrorCode::PrematureEndOfFileError: return "premature end of file (truncated?)";
    case vtkErrorCode::FileFormatError: return "file format error";
    case vtkErrorCode::NoFileNameError: return "no file name";
    default: return "VTK reader error " + std::to_string(code);
  }
}

// Collects the first error a VTK object reports, and keeps errors and
// warnings off the console (the loader reports them as InputError instead).
class VtkErrorCatcher : public vtkCommand {
 public:
  static VtkErrorCatcher* New() { return new VtkErrorCatcher; }
  void Execute(vtkObject*, unsigned long event, void* callData) override {
    if (event == vtkCommand::ErrorEvent && message.empty())
      message = callData ? CleanVtkMessage(static_cast<const char*>(callData)) : "unknown VTK error";
  }
  std::string message;
};

// Records the first error or warning that reaches the output window.
// Readers report some failures only there, from helper functions that have
// no object to observe: vtkImageReader's "File operation failed" on a short
// raw file, vtkDataReader's "Error reading binary data!", the XML parser's
// syntax errors.
class CapturingOutputWindow : public vtkOutputWindow {
 public:
  static CapturingOutputWindow* New() {
    auto* window = new CapturingOutputWindow;
    window->InitializeObjectBase();
    return window;
  }
  vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow)
  void DisplayErrorText(const char* text) override { Record(text); }
  void DisplayWarningText(const char* text) override { Record(text); }
  void DisplayGenericWarningText(const char* text) override { Record(text); }
  std::string message;

 private:
  void Record(const char* text) {
    if (message.empty()) message = text ? CleanVtkMessage(text) : "unknown VTK error";
  }
};

// Watches a reader, its executive and the output window for errors while it
// lives. The output window is process-wide: loading is meant for one thread.
class ReaderErrors {
 public:
  explicit ReaderErrors(vtkAlgorithm* reader) : reader_(reader), previousWindow_(vtkOutputWindow::GetInstance()) {
    readerTags_[0] = reader->AddObserver(vtkCommand::ErrorEvent, readerCatcher_);
    readerTags_[1] = reader->AddObserver(vtkCommand::WarningEvent, readerCatcher_);
    executiveTag_ = reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, executiveCatcher_);
    vtkOutputWindow::SetInstance(window_);
  }
  ~ReaderErrors() {
    vtkOutputWindow::SetInstance(previousWindow_);
    reader_->RemoveObserver(readerTags_[0]);
    reader_->RemoveObserver(readerTags_[1]);
    reader_->GetExecutive()->RemoveObserver(executiveTag_);
  }
  ReaderErrors(const ReaderErrors&) = delete;
  ReaderErrors& operator=(const ReaderErrors&) = delete;

  // Throws InputError naming `path` if the reader reported an error.
  void ThrowIfFailed(const std::string& path) const {
    if (!readerCatcher_->message.empty()) throw InputError(path + ": cannot read: " + readerCatcher_->message);
    if (!window_->message.empty()) throw InputError(path + ": cannot read: " + window_->message);
    if (reader_->GetErrorCode() != vtkErrorCode::NoError)
      throw InputError(path + ": cannot read: " + DescribeVtkErrorCode(reader_->GetErrorCode()));
    // The executive's own messages are long pipeline dumps: report only the failure.
    if (!executiveCatcher_->message.empty()) throw InputError(path + ": cannot read (the reader failed)");
  }

 private:
  vtkAlgorithm* reader_;
  vtkSmartPointer<vtkOutputWindow> previousWindow_;
  vtkNew<CapturingOutputWindow> window_;
  vtkNew<VtkErrorCatcher> readerCatcher_, executiveCatcher_;
  unsigned long readerTags_[2] = {0, 0}, executiveTag_ = 0;
};

// Runs a reader and returns its image, which the reader owns. Throws
// InputError when the reader fails or produces no voxels.
vtkImageData* RunReader(vtkAlgorithm* reader, const std::string& path) {
  ReaderErrors errors(reader);
  reader->Update();
  errors.ThrowIfFailed(path);
  vtkImageData* image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
  if (!image) throw InputError(path + ": cannot read: the reader produced no image");
  const int* d = image->GetDimensions();
  if (d[0] <= 0 || d[1] <= 0 || d[2] <= 0 || image->GetNumberOfPoints() == 0)
    throw InputError(path + ": empty volume (no voxels)");
  return image;
}

// The point-data array that holds the voxels: the active scalars, else the
// only point array (VTI files need not mark their scalars active).
vtkDataArray* VoxelArray(vtkImageData* image, const std::string& path) {
  vtkPointData* pd = image->GetPointData();
  vtkDataArray* a = pd->GetScalars();
  if (!a && pd->GetNumberOfArrays() >= 1) a = pd->GetArray(0);
  if (!a) throw InputError(path + ": holds no scalar point data");
  return a;
}

SourceType SourceTypeOfVtk(int vtkType, const std::string& path) {
  switch (vtkType) {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR: return SourceType::Int8;
    case VTK_UNSIGNED_CHAR: return SourceType::UInt8;
    case VTK_SHORT: return SourceType::Int16;
    case VTK_UNSIGNED_SHORT: return SourceType::UInt16;
    case VTK_INT: return SourceType::Int32;
    case VTK_UNSIGNED_INT: return SourceType::UInt32;
    case VTK_LONG: return sizeof(long) == 8 ? SourceType::Int64 : SourceType::Int32;
    case VTK_UNSIGNED_LONG: return sizeof(long) == 8 ? SourceType::UInt64 : SourceType::UInt32;
    case VTK_LONG_LONG:
    case VTK_ID_TYPE: return SourceType::Int64;
    case VTK_UNSIGNED_LONG_LONG: return SourceType::UInt64;
    case VTK_FLOAT: return SourceType::Float32;
    case VTK_DOUBLE: return SourceType::Float64;
    default:
      throw InputError(path + ": unsupported voxel type " + vtkImageScalarTypeNameMacro(vtkType));
  }
}

// Copies a single-component image's voxels into `out` (dims, type, voxels).
void StoreImageVoxels(vtkImageData* image, const std::string& path, Rescale rescale, HostVolume& out) {
  vtkDataArray* a = VoxelArray(image, path);
  if (a->GetNumberOfComponents() != 1) ThrowComponents(path, a->GetNumberOfComponents());
  const int* d = image->GetDimensions();
  out.dims = {d[0], d[1], d[2]};
  if (a->GetNumberOfTuples() != out.VoxelCount())
    throw InputError(path + ": holds " + std::to_string(a->GetNumberOfTuples()) + " voxels, expected " +
                     std::to_string(out.VoxelCount()) + " (truncated or corrupt?)");
  StoreVoxels(a->GetVoidPointer(0), SourceTypeOfVtk(a->GetDataType(), path), out.VoxelCount(), rescale, out);
}

// x_world = origin + D * (spacing * index), with index 0 at the first stored
// voxel. VTK images may start at a non-zero extent; fold that into the origin.
Affine3 VtkImageIndexToWorld(vtkImageData* image) {
  const double* o = image->GetOrigin();
  const double* s = image->GetSpacing();
  const int* e = image->GetExtent();
  Mat3d d = kIdentity3;
  if (vtkMatrix3x3* m = image->GetDirectionMatrix())
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) d[3 * r + c] = m->GetElement(r, c);
  Vec3d origin;
  for (int r = 0; r < 3; ++r) {
    origin[r] = o[r];
    for (int c = 0; c < 3; ++c) origin[r] += d[3 * r + c] * s[c] * e[2 * c];
  }
  return IndexToWorld(origin, {s[0], s[1], s[2]}, d);
}

// ---------------------------------------------------------------------------
// 4a. NRRD
// ---------------------------------------------------------------------------
// vtkNrrdReader reads the voxels, but its geometry is not usable: it ignores
// the direction of `space directions` (keeping only their lengths), leaves
// `space origin` in the file's space, reverses the rows of raw-encoded files
// in left-handed spaces (LAS), and takes a fastest axis of 9 or fewer samples
// for vector components. So the geometry and the axis layout come from our
// own parse of the header, and the voxels are put back in file order.

struct NrrdHeader {
  int dimension = 0;
  std::vector<int64_t> sizes;
  std::string space;     // lower-case, "" if absent
  std::string encoding;  // lower-case, "raw" if absent
  bool hasSpaceDirections = false;
  std::vector<std::optional<Vec3d>> directions;  // per axis; nullopt = "none"
  std::optional<Vec3d> origin;
  std::vector<double> spacings;  // per axis, from the older `spacings` field
};

// "(a,b,c)" -> vector; "none" -> nullopt. Throws on anything else.
std::optional<Vec3d> ParseNrrdVector(const std::string& token, const std::string& path) {
  if (token == "none") return std::nullopt;
  std::string inner = token;
  if (inner.size() < 2 || inner.front() != '(' || inner.back() != ')')
    throw InputError(path + ": bad NRRD vector '" + token + "'");
  inner = inner.substr(1, inner.size() - 2);
  std::replace(inner.begin(), inner.end(), ',', ' ');
  const std::vector<double> v = ParseNumbers(inner);
  if (v.size() != 3) throw InputError(path + ": NRRD vector '" + token + "' does not have 3 components");
  return Vec3d{v[0], v[1], v[2]};
}

// Splits "(1,0,0) (0, 1, 0) none" into vector tokens, allowing spaces inside parentheses.
std::vector<std::string> SplitNrrdVectors(const std::string& text) {
  std::vector<std::string> tokens;
  std::string current;
  int depth = 0;
  for (char c : text) {
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (std::isspace((unsigned char)c) && depth == 0) {
      if (!current.empty()) tokens.push_back(current);
      current.clear();
    } else if (!std::isspace((unsigned char)c)) {
      current += c;
    }
  }
  if (!current.empty()) tokens.push_back(current);
  return tokens;
}

// Reads the header lines: up to the first blank line (a detached .nhdr header
// is the whole file). Stops after 1 MiB so a file without a blank line is not
// scanned as text to its end.
std::vector<std::string> ReadNrrdHeaderLines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::vector<std::string> lines;
  std::string line;
  size_t bytes = 0;
  while (std::getline(in, line) && bytes < (1u << 20)) {
    bytes += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;
    lines.push_back(line);
  }
  if (lines.empty() || lines[0].rfind("NRRD", 0) != 0) throw InputError(path + ": not a NRRD file (no NRRD magic)");
  return lines;
}

NrrdHeader ParseNrrdHeader(const std::string& path) {
  NrrdHeader h;
  const std::vector<std::string> lines = ReadNrrdHeaderLines(path);
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (line[0] == '#') continue;
    const size_t colon = line.find(": ");
    if (colon == std::string::npos) continue;  // "key:=value" pairs and junk carry no geometry
    const std::string field = Trim(line.substr(0, colon)), value = Trim(line.substr(colon + 2));
    if (field == "dimension") {
      h.dimension = std::atoi(value.c_str());
    } else if (field == "sizes") {
      for (double v : ParseNumbers(value)) {
        if (!(v >= 1 && v <= std::numeric_limits<int>::max() && v == std::floor(v)))
          throw InputError(path + ": NRRD 'sizes' must be positive integers: " + value);
        h.sizes.push_back((int64_t)v);
      }
    } else if (field == "space") {
      h.space = ToLower(value);
    } else if (field == "encoding") {
      h.encoding = ToLower(value);
    } else if (field == "space directions") {
      h.hasSpaceDirections = true;
      for (const std::string& token : SplitNrrdVectors(value)) h.directions.push_back(ParseNrrdVector(token, path));
    } else if (field == "space origin") {
      h.origin = ParseNrrdVector(value, path);
    } else if (field == "spacings") {
      std::istringstream in(value);
      std::string token;
      while (in >> token) h.spacings.push_back(ToLower(token) == "nan" ? std::nan("") : std::atof(token.c_str()));
    }
  }
  if (h.encoding.empty()) h.encoding = "raw";
  if (h.dimension <= 0 || (int)h.sizes.size() != h.dimension)
    throw InputError(path + ": NRRD header has no valid 'dimension' and 'sizes'");
  if (h.hasSpaceDirections && (int)h.directions.size() != h.dimension)
    throw InputError(path + ": NRRD 'space directions' has " + std::to_string(h.directions.size()) +
                     " entries for " + std::to_string(h.dimension) + " axes");
  return h;
}

// Per-axis signs that take coordinates of a NRRD space to LPS. Spaces
// without anatomy (scanner-xyz, 3D-right-handed, ...) are taken as they are.
Vec3d NrrdSpaceToLps(const std::string& space) {
  if (space == "right-anterior-superior" || space == "ras") return {-1, -1, 1};
  if (space == "left-anterior-superior" || space == "las") return {1, -1, 1};
  return {1, 1, 1};
}

// The axes that are space, not vector components: those with a direction
// when `space directions` is given; else all of them, except that a 4-axis
// file's fastest axis is the components axis (vtkNrrdReader's assumption).
std::vector<int> NrrdSpatialAxes(const NrrdHeader& h) {
  std::vector<int> axes;
  for (int a = 0; a < h.dimension; ++a) {
    if (h.hasSpaceDirections ? h.directions[a].has_value() : !(h.dimension == 4 && a == 0)) axes.push_back(a);
  }
  return axes;
}

// Index -> LPS world from `space directions` and `space origin` (or the
// older `spacings`, with an identity direction), for the spatial axes.
Affine3 NrrdIndexToWorld(const NrrdHeader& h, const std::vector<int>& spatial, const std::string& path) {
  const Vec3d toLps = NrrdSpaceToLps(h.space);
  Vec3d origin{0, 0, 0}, spacing{1, 1, 1};
  Mat3d direction = kIdentity3;
  if (h.origin)
    for (int r = 0; r < 3; ++r) origin[r] = (*h.origin)[r] * toLps[r];
  for (int c = 0; c < (int)spatial.size(); ++c) {
    const int axis = spatial[c];
    if (h.hasSpaceDirections) {
      const Vec3d& v = *h.directions[axis];
      spacing[c] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      if (!(spacing[c] > 0) || !std::isfinite(spacing[c]))
        throw InputError(path + ": NRRD space direction of axis " + std::to_string(axis) + " is zero or not finite");
      for (int r = 0; r < 3; ++r) direction[3 * r + c] = v[r] * toLps[r] / spacing[c];
    } else if (axis < (int)h.spacings.size() && std::isfinite(h.spacings[axis]) && h.spacings[axis] != 0) {
      spacing[c] = h.spacings[axis];
    }
  }
  // A 2D image's missing k axis: the plane normal, so the matrix stays invertible.
  if (spatial.size() == 2 && h.hasSpaceDirections) {
    const Vec3d n = Cross({direction[0], direction[3], direction[6]}, {direction[1], direction[4], direction[7]});
    const double length = std::sqrt(Dot(n, n));
    for (int r = 0; r < 3; ++r) direction[3 * r + 2] = length > 0 ? n[r] / length : kIdentity3[3 * r + 2];
  }
  return IndexToWorld(origin, spacing, direction);
}

void LoadNrrd(const std::string& path, HostVolume& out) {
  const NrrdHeader h = ParseNrrdHeader(path);
  const std::vector<int> spatial = NrrdSpatialAxes(h);
  int64_t components = 1;
  for (int a = 0; a < h.dimension; ++a)
    if (std::find(spatial.begin(), spatial.end(), a) == spatial.end()) components *= h.sizes[a];
  if (components != 1) ThrowComponents(path, components);
  if (spatial.empty() || spatial.size() > 3)
    throw InputError(path + ": a NRRD volume needs 1 to 3 spatial axes, this one has " +
                     std::to_string(spatial.size()));

  vtkNew<vtkNrrdReader> reader;
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path);
  vtkDataArray* a = VoxelArray(image, path);

  // The axis layout comes from our header; the buffer is the same whatever
  // vtkNrrdReader made of the axes (x fastest either way).
  for (int i = 0; i < 3; ++i) out.dims[i] = i < (int)spatial.size() ? (int)h.sizes[spatial[i]] : 1;
  const int64_t values = (int64_t)a->GetNumberOfTuples() * a->GetNumberOfComponents();
  if (values != out.VoxelCount())
    throw InputError(path + ": holds " + std::to_string(values) + " voxels, expected " +
                     std::to_string(out.VoxelCount()) + " (truncated or corrupt?)");
  StoreVoxels(a->GetVoidPointer(0), SourceTypeOfVtk(a->GetDataType(), path), out.VoxelCount(), Rescale{}, out);
  // vtkImageReader2 (raw encoding only) stores the rows of each slice bottom
  // up when FileLowerLeft is off; undo that in the reader's own row layout,
  // which may differ from ours when it took the x axis for components.
  if (!reader->GetFileLowerLeft() && h.encoding == "raw") {
    const int* vtkDims = image->GetDimensions();
    ReverseRuns(out, (int64_t)vtkDims[0] * a->GetNumberOfComponents(), vtkDims[1]);
  }

  out.indexToWorld = NrrdIndexToWorld(h, spatial, path);
}

// ---------------------------------------------------------------------------
// 4b. NIfTI
// ---------------------------------------------------------------------------
// vtkNIFTIImageReader gives a matrix M (sform, else qform) from VTK data
// coordinates (origin + spacing * index) to NIfTI world, which is RAS. When
// qfac is -1 (or the sform is left-handed and there is no qform) it reverses
// the slice order and adjusts M to match, so M always fits the stored voxels.

// Index -> LPS world: the sform if there is one, else the qform. With
// neither, NIfTI coordinates are the scaled index (method 1), still in RAS,
// as ITK and nibabel read them.
Affine3 NiftiIndexToWorld(vtkNIFTIImageReader* reader, vtkImageData* image) {
  vtkMatrix4x4* m = reader->GetSFormMatrix() ? reader->GetSFormMatrix() : reader->GetQFormMatrix();
  vtkNew<vtkMatrix4x4> identity;
  if (!m) m = identity;
  const Vec3d rasToLps{-1, -1, 1};
  const double* o = image->GetOrigin();
  const double* s = image->GetSpacing();
  const int* e = image->GetExtent();
  Mat3d direction;
  Vec3d origin;
  for (int r = 0; r < 3; ++r) {
    double world = m->GetElement(r, 3);
    for (int c = 0; c < 3; ++c) {
      direction[3 * r + c] = rasToLps[r] * m->GetElement(r, c);
      world += m->GetElement(r, c) * (o[c] + s[c] * e[2 * c]);
    }
    origin[r] = rasToLps[r] * world;
  }
  return IndexToWorld(origin, {s[0], s[1], s[2]}, direction);
}

void LoadNifti(const std::string& path, HostVolume& out) {
  vtkNew<vtkNIFTIImageReader> reader;
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path);
  if (reader->GetTimeDimension() > 1)
    throw InputError(path + ": has " + std::to_string(reader->GetTimeDimension()) +
                     " time points; a single 3D volume is needed");

  // scl_slope == 0 means "no scaling" in the NIfTI standard.
  Rescale rescale;
  const double slope = reader->GetRescaleSlope(), intercept = reader->GetRescaleIntercept();
  if (slope != 0 && std::isfinite(slope) && std::isfinite(intercept)) rescale = {slope, intercept};
  StoreImageVoxels(image, path, rescale, out);
  out.indexToWorld = NiftiIndexToWorld(reader, image);
}

// ---------------------------------------------------------------------------
// 4c. MetaImage
// ---------------------------------------------------------------------------
// vtkMetaImageReader ignores TransformMatrix, so the geometry comes from the
// header text. As in ITK, TransformMatrix lists the direction of axis 0, then
// of axis 1, then of axis 2, in LPS; AnatomicalOrientation is ignored (ITK
// does the same on reading).

struct MetaImageHeader {
  std::map<std::string, std::string> fields;  // "Key = Value" pairs
  uint64_t size = 0;                          // bytes up to and including the ElementDataFile line
};

MetaImageHeader ReadMetaImageHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  MetaImageHeader h;
  std::string line;
  while (h.size < (1u << 20) && std::getline(in, line)) {
    h.size += line.size() + 1;
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = Trim(line.substr(0, eq));
    h.fields[key] = Trim(line.substr(eq + 1));
    if (key == "ElementDataFile") break;
  }
  return h;
}

// The number of bytes the zlib (or gzip) stream at `offset` of `file`
// inflates to. Throws if the stream is damaged or cut short.
uint64_t InflatedSize(const std::string& file, uint64_t offset, const std::string& where) {
  std::ifstream in(file, std::ios::binary);
  if (!in.seekg((std::streamoff)offset)) throw InputError(where + ": cannot read " + file);
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK) throw InputError(where + ": zlib failed to start");  // +32: zlib or gzip
  std::vector<unsigned char> input(1 << 16), output(1 << 18);
  uint64_t total = 0;
  int ret = Z_OK;
  while (ret != Z_STREAM_END) {
    if (zs.avail_in == 0) {
      in.read(reinterpret_cast<char*>(input.data()), (std::streamsize)input.size());
      if (in.gcount() == 0) break;
      zs.next_in = input.data();
      zs.avail_in = (uInt)in.gcount();
    }
    zs.next_out = output.data();
    zs.avail_out = (uInt)output.size();
    ret = inflate(&zs, Z_NO_FLUSH);
    if (ret != Z_OK && ret != Z_STREAM_END && ret != Z_BUF_ERROR) break;
    total += output.size() - zs.avail_out;
  }
  inflateEnd(&zs);
  if (ret != Z_STREAM_END)
    throw InputError(where + ": compressed voxel data in " + fs::path(file).filename().string() +
                     " is damaged or cut short (truncated?)");
  return total;
}

// metaio reports a short or damaged data file only on the console and
// returns what it read, so check that all `bytes` of voxel data are there.
// Data split over several files (LIST, patterns) is left to the reader.
void CheckMetaImageData(const std::string& path, const MetaImageHeader& h, uint64_t bytes) {
  auto field = [&](const char* key) {
    auto it = h.fields.find(key);
    return it == h.fields.end() ? std::string() : it->second;
  };
  const std::string dataName = field("ElementDataFile");
  if (dataName.empty() || dataName == "LIST" || dataName.find('%') != std::string::npos) return;
  const long headerSize = field("HeaderSize").empty() ? 0 : std::atol(field("HeaderSize").c_str());
  if (headerSize < 0) return;  // -1: data at the end of the file, any size
  const bool local = dataName == "LOCAL";
  const std::string dataFile = local ? path : (fs::path(path).parent_path() / dataName).string();
  const uint64_t offset = (local ? h.size : 0) + (uint64_t)headerSize;
  std::error_code ec;
  const uint64_t fileSize = fs::file_size(dataFile, ec);
  if (ec) throw InputError(path + ": cannot open its data file " + dataName);
  const bool compressed = ToLower(field("CompressedData")) == "true";
  const uint64_t available =
      compressed ? InflatedSize(dataFile, offset, path) : (fileSize > offset ? fileSize - offset : 0);
  if (available < bytes)
    throw InputError(path + ": voxel data is " + std::to_string(available) + " bytes, expected " +
                     std::to_string(bytes) + " (truncated?)");
}

// The first of `keys` present with exactly `n` numbers.
std::optional<std::vector<double>> MetaNumbers(const std::map<std::string, std::string>& fields,
                                               std::initializer_list<const char*> keys, size_t n) {
  for (const char* key : keys) {
    auto it = fields.find(key);
    if (it == fields.end()) continue;
    std::vector<double> v = ParseNumbers(it->second);
    if (v.size() == n) return v;
  }
  return std::nullopt;
}

void LoadMetaImage(const std::string& path, HostVolume& out) {
  const MetaImageHeader header = ReadMetaImageHeader(path);
  const auto& fields = header.fields;
  if (fields.find("ObjectType") == fields.end() && fields.find("NDims") == fields.end())
    throw InputError(path + ": not a MetaImage header (no ObjectType or NDims)");
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path);
  vtkDataArray* a = VoxelArray(image, path);
  CheckMetaImageData(path, header, (uint64_t)a->GetNumberOfValues() * (uint64_t)a->GetDataTypeSize());
  StoreImageVoxels(image, path, Rescale{}, out);

  // 2D images (NDims 2) keep VTK's origin and spacing, with an identity direction.
  const double* o = image->GetOrigin();
  const double* s = image->GetSpacing();
  Vec3d origin{o[0], o[1], o[2]}, spacing{s[0], s[1], s[2]};
  Mat3d direction = kIdentity3;
  if (auto v = MetaNumbers(fields, {"Offset", "Position", "Origin"}, 3)) origin = {(*v)[0], (*v)[1], (*v)[2]};
  if (auto v = MetaNumbers(fields, {"ElementSpacing", "ElementSize"}, 3)) spacing = {(*v)[0], (*v)[1], (*v)[2]};
  if (auto v = MetaNumbers(fields, {"TransformMatrix", "Rotation", "Orientation"}, 9))
    for (int axis = 0; axis < 3; ++axis)
      for (int r = 0; r < 3; ++r) direction[3 * r + axis] = (*v)[3 * axis + r];
  out.indexToWorld = IndexToWorld(origin, spacing, direction);
}

// ---------------------------------------------------------------------------
// 4d. VTK XML image data (.vti) and legacy structured points (.vtk)
// ---------------------------------------------------------------------------
// Scientific data without anatomy: the coordinates are taken as LPS as they
// are. VTI files may carry a Direction matrix, which vtkImageData keeps.

void LoadVti(const std::string& path, HostVolume& out) {
  vtkNew<vtkXMLImageDataReader> reader;
  if (!reader->CanReadFile(path.c_str())) throw InputError(path + ": not a VTK XML ImageData file");
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

void LoadLegacyVtk(const std::string& path, HostVolume& out) {
  vtkNew<vtkStructuredPointsReader> reader;
  reader->SetFileName(path.c_str());
  {
    ReaderErrors errors(reader);
    if (!reader->IsFileStructuredPoints()) {
      errors.ThrowIfFailed(path);
      throw InputError(path + ": not a legacy VTK STRUCTURED_POINTS dataset");
    }
  }
  vtkImageData* image = RunReader(reader, path);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

// ---------------------------------------------------------------------------
// 4e. DICOM folder
// ---------------------------------------------------------------------------
// vtkDICOMImageReader reads uncompressed series only, and aborts the process
// on some compressed ones (JPEG 2000), so the transfer syntax of every file is
// checked first. It applies the rescale slope/intercept itself, sorts the
// slices by position along the slice normal (descending) and stores each
// slice bottom row first. We store the voxels in DICOM order instead (rows as
// in the file, slices ascending along the normal, as ITK/GDCM do), so that
// index (0,0,0) is the first pixel of the first slice and its
// ImagePositionPatient is the origin.

// The TransferSyntaxUID (0002,0010) from a Part 10 file's meta header; "" if
// the file has no "DICM" preamble (an old ACR-NEMA file or not DICOM).
std::string ReadDicomTransferSyntax(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  if (!in.seekg(128) || !in.read(magic, 4) || std::memcmp(magic, "DICM", 4) != 0) return "";
  // Group 0002 is always explicit VR little endian.
  for (int element = 0; element < 64; ++element) {
    uint8_t tag[8];
    if (!in.read(reinterpret_cast<char*>(tag), 8)) return "";
    const unsigned group = tag[0] | (tag[1] << 8), elem = tag[2] | (tag[3] << 8);
    if (group != 0x0002) return "";
    const std::string vr(reinterpret_cast<char*>(tag + 4), 2);
    uint32_t length = tag[6] | (tag[7] << 8);
    if (vr == "OB" || vr == "OW" || vr == "OF" || vr == "SQ" || vr == "UT" || vr == "UN" || vr == "UC" ||
        vr == "UR" || vr == "OD" || vr == "OL" || vr == "OV") {
      uint8_t len32[4];
      if (!in.read(reinterpret_cast<char*>(len32), 4)) return "";
      length = len32[0] | (len32[1] << 8) | (len32[2] << 16) | ((uint32_t)len32[3] << 24);
    }
    if (length > (1u << 16)) return "";
    std::string value(length, '\0');
    if (!in.read(&value[0], length)) return "";
    if (elem == 0x0010) return Trim(value.substr(0, value.find('\0')));
  }
  return "";
}

// The syntaxes vtkDICOMImageReader can decode: implicit/explicit little
// endian and explicit big endian, all uncompressed.
bool IsUncompressedTransferSyntax(const std::string& uid) {
  return uid == "1.2.840.10008.1.2" || uid == "1.2.840.10008.1.2.1" || uid == "1.2.840.10008.1.2.2";
}

std::string DescribeTransferSyntax(const std::string& uid) {
  if (uid == "1.2.840.10008.1.2.4.90" || uid == "1.2.840.10008.1.2.4.91") return "JPEG 2000 compressed";
  if (uid.rfind("1.2.840.10008.1.2.4.20", 0) == 0) return "High-Throughput JPEG 2000 compressed";
  if (uid == "1.2.840.10008.1.2.4.80" || uid == "1.2.840.10008.1.2.4.81") return "JPEG-LS compressed";
  if (uid.rfind("1.2.840.10008.1.2.4.", 0) == 0) return "JPEG compressed";
  if (uid == "1.2.840.10008.1.2.5") return "RLE compressed";
  if (uid == "1.2.840.10008.1.2.1.99") return "deflate compressed";
  return "compressed or unknown transfer syntax";
}

// The regular files of a folder, sorted; DICOMDIR (a CD's index, no image)
// is left out.
std::vector<std::string> ListFiles(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file(ec) && ToLower(entry.path().filename().string()) != "dicomdir")
      files.push_back(entry.path().string());
  if (ec) throw InputError(folder + ": cannot list the folder: " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

// Throws before vtkDICOMImageReader sees a file it cannot decode. Returns
// how many files are DICOM Part 10 files (with a "DICM" preamble).
int CheckDicomTransferSyntaxes(const std::string& folder, const std::vector<std::string>& files) {
  int part10 = 0;
  for (const std::string& file : files) {
    const std::string uid = ReadDicomTransferSyntax(file);
    if (uid.empty()) continue;
    ++part10;
    if (!IsUncompressedTransferSyntax(uid))
      throw InputError(folder + ": " + fs::path(file).filename().string() + " is " + DescribeTransferSyntax(uid) +
                       " DICOM (transfer syntax " + uid +
                       "); it needs the ITK/GDCM reader, which is not built (MMRTM_ENABLE_ITK)");
  }
  return part10;
}

// vtkDICOMImageReader keeps its sorted file list protected in VTK 9.1; this
// subclass only makes it readable.
class DicomSeriesReader : public vtkDICOMImageReader {
 public:
  static DicomSeriesReader* New() {
    auto* reader = new DicomSeriesReader;
    reader->InitializeObjectBase();
    return reader;
  }
  vtkTypeMacro(DicomSeriesReader, vtkDICOMImageReader)
  int SliceFileCount() { return GetNumberOfDICOMFileNames(); }
  std::string SliceFile(int i) { return GetDICOMFileName(i); }
};

// What one slice file's header says about its place and pixel layout.
struct DicomSliceHeader {
  std::string file;
  Vec3d position;             // ImagePositionPatient, LPS mm
  std::array<double, 6> iop;  // ImageOrientationPatient: row direction, column direction
  int width = 0, height = 0, bitsAllocated = 0, components = 0;
};

// Reads one file's header (no pixels).
DicomSliceHeader ReadDicomSliceHeader(const std::string& file) {
  vtkNew<vtkDICOMImageReader> reader;
  reader->SetFileName(file.c_str());
  ReaderErrors errors(reader);
  reader->UpdateInformation();
  errors.ThrowIfFailed(file);
  DicomSliceHeader h;
  h.file = file;
  const float* p = reader->GetImagePositionPatient();
  const float* o = reader->GetImageOrientationPatient();
  for (int i = 0; i < 3; ++i) h.position[i] = p[i];
  for (int i = 0; i < 6; ++i) h.iop[i] = o[i];
  h.width = reader->GetWidth();
  h.height = reader->GetHeight();
  h.bitsAllocated = reader->GetBitsAllocated();
  h.components = reader->GetNumberOfComponents();
  return h;
}

// vtkDICOMImageReader copies every slice with the first slice's row length
// and row count, and does not notice a file cut short: a slice of another
// size would make it read or write out of bounds, a short file gives garbage.
// So every slice must match the first, and each file must be big enough to
// hold its pixels (a file cut inside its few-kB header can still pass).
void CheckDicomSlicesMatch(const std::string& folder, const std::vector<DicomSliceHeader>& slices) {
  const DicomSliceHeader& first = slices.front();
  const uint64_t pixelBytes =
      (uint64_t)first.width * first.height * std::max(first.components, 1) * ((first.bitsAllocated + 7) / 8);
  for (const DicomSliceHeader& s : slices) {
    const std::string name = fs::path(s.file).filename().string();
    if (s.width != first.width || s.height != first.height || s.bitsAllocated != first.bitsAllocated ||
        s.components != first.components)
      throw InputError(folder + ": " + name + " is " + std::to_string(s.width) + " x " + std::to_string(s.height) +
                       " with " + std::to_string(s.bitsAllocated) + "-bit pixels, unlike the first slice (" +
                       std::to_string(first.width) + " x " + std::to_string(first.height) + ", " +
                       std::to_string(first.bitsAllocated) + "-bit)");
    std::error_code ec;
    if (fs::file_size(s.file, ec) < pixelBytes + 132)  // 128-byte preamble + "DICM"
      throw InputError(folder + ": " + name + " is too short for its pixel data (truncated?)");
  }
}

// The world offset from one slice to the next, from the first and last
// ImagePositionPatient. Throws when the slices are not evenly spaced along
// it (a missing slice, mixed series): the volume grid would misplace them.
Vec3d DicomSliceStep(const std::string& folder, const std::vector<DicomSliceHeader>& slices, double thickness) {
  const int n = (int)slices.size();
  const Vec3d row{slices[0].iop[0], slices[0].iop[1], slices[0].iop[2]};
  const Vec3d column{slices[0].iop[3], slices[0].iop[4], slices[0].iop[5]};
  Vec3d step;
  if (n == 1) {  // one slice: its thickness along the normal
    const Vec3d normal = Cross(row, column);
    for (int r = 0; r < 3; ++r) step[r] = normal[r] * thickness;
    return step;
  }
  for (int r = 0; r < 3; ++r) step[r] = (slices[n - 1].position[r] - slices[0].position[r]) / (n - 1);
  const double length = std::sqrt(Dot(step, step));
  if (!(length > 0)) throw InputError(folder + ": all slices share one position (not a volume series?)");
  for (int i = 0; i < n; ++i) {
    Vec3d offset;
    for (int r = 0; r < 3; ++r) offset[r] = slices[i].position[r] - (slices[0].position[r] + i * step[r]);
    if (std::sqrt(Dot(offset, offset)) > 0.1 * length)
      throw InputError(folder + ": slices are not evenly spaced (" + fs::path(slices[i].file).filename().string() +
                       " is " + std::to_string(std::sqrt(Dot(offset, offset))) +
                       " mm off the regular grid; a missing slice?)");
  }
  return step;
}

void LoadDicomFolder(const std::string& folder, HostVolume& out) {
  const std::vector<std::string> files = ListFiles(folder);
  if (files.empty())
    throw InputError(folder + ": the folder holds no files (expected the DICOM files of one series)");
  const int part10Files = CheckDicomTransferSyntaxes(folder, files);

  vtkNew<DicomSeriesReader> reader;
  reader->SetDirectoryName(folder.c_str());
  {
    ReaderErrors errors(reader);
    reader->UpdateInformation();
    if (reader->SliceFileCount() == 0) throw InputError(folder + ": the folder holds no DICOM files");
    errors.ThrowIfFailed(folder);
  }
  // The reader keeps the first series and drops files it cannot place.
  const int n = reader->SliceFileCount();
  if (part10Files > n)
    throw InputError(folder + ": holds " + std::to_string(part10Files) + " DICOM files but only " +
                     std::to_string(n) + " form the series (a damaged file, or more than one series?)");
  std::vector<DicomSliceHeader> slices;
  for (int i = 0; i < n; ++i) slices.push_back(ReadDicomSliceHeader(reader->SliceFile(i)));
  CheckDicomSlicesMatch(folder, slices);

  vtkImageData* image = RunReader(reader, folder);
  StoreImageVoxels(image, folder, Rescale{}, out);  // the reader has rescaled already
  if (out.dims[2] != n || out.dims[0] != slices[0].width || out.dims[1] != slices[0].height)
    throw InputError(folder + ": the DICOM reader returned an unexpected volume size");

  // Slices in the reader's order (descending along the normal) -> ascending.
  Vec3d step = DicomSliceStep(folder, slices, image->GetSpacing()[2]);
  const Vec3d row{slices[0].iop[0], slices[0].iop[1], slices[0].iop[2]};
  const Vec3d column{slices[0].iop[3], slices[0].iop[4], slices[0].iop[5]};
  const bool reverseSlices = Dot(step, Cross(row, column)) < 0;
  Vec3d origin = slices[0].position;
  if (reverseSlices) {
    origin = slices[n - 1].position;
    for (double& v : step) v = -v;
  }
  ReverseRuns(out, out.dims[0], out.dims[1]);  // rows back to file order (top row first)
  if (reverseSlices) ReverseRuns(out, (int64_t)out.dims[0] * out.dims[1], out.dims[2]);

  // PixelSpacing is (row spacing, column spacing): the first value is the
  // distance between rows (y), the second between columns (x); the reader
  // keeps them in that order as its x and y spacing.
  const double dx = image->GetSpacing()[1], dy = image->GetSpacing()[0];
  const double dz = std::sqrt(Dot(step, step));
  // A gantry tilt makes `step` oblique to the normal; keeping the real step
  // (a sheared grid) puts every slice where its ImagePositionPatient says.
  Mat3d direction;
  for (int r = 0; r < 3; ++r) {
    direction[3 * r + 0] = row[r];
    direction[3 * r + 1] = column[r];
    direction[3 * r + 2] = step[r] / dz;
  }
  out.indexToWorld = IndexToWorld(origin, {dx, dy, dz}, direction);
}

// ---------------------------------------------------------------------------
// 4f. InVesalius project (.inv3)
// ---------------------------------------------------------------------------
// A gzip-compressed tar holding main.plist (Apple XML plist) and the raw
// little-endian voxel file it names (x fastest). The project keeps no
// patient orientation. Its rows run from posterior to anterior (the face of
// Cranium.inv3 is at the last rows, its head holder at the first), the
// opposite of DICOM's: the y axis is flipped so that +y is posterior (LPS),
// and a camera on the anterior side sees the face. (ct_head_cranium.nrrd
// holds the same voxels with an identity direction; it shows the face at +y.)

// Sequential reads through zlib (plain, uncompressed files read as they are).
class GzipReader {
 public:
  explicit GzipReader(const std::string& path) : path_(path), file_(gzopen(path.c_str(), "rb")) {
    if (!file_) throw InputError(path + ": cannot open");
  }
  ~GzipReader() { gzclose(file_); }
  GzipReader(const GzipReader&) = delete;
  GzipReader& operator=(const GzipReader&) = delete;

  // Reads up to n bytes; fewer only at the end of the data. Throws on
  // corrupt data, on a CRC mismatch at the end of the stream and on a stream
  // cut short (zlib reports that as an end of data with Z_BUF_ERROR set).
  uint64_t Read(void* buffer, uint64_t n) {
    uint64_t done = 0;
    while (done < n) {
      const unsigned chunk = (unsigned)std::min<uint64_t>(n - done, 1u << 30);
      const int got = gzread(file_, static_cast<char*>(buffer) + done, chunk);
      int code = Z_OK;
      const char* msg = gzerror(file_, &code);
      if (got < 0 || code != Z_OK) {
        std::string what = msg ? msg : "zlib error";
        if (what.rfind(path_ + ": ", 0) == 0) what = what.substr(path_.size() + 2);  // zlib prefixes the path
        throw InputError(path_ + ": corrupt or truncated gzip data (" + what + ")");
      }
      if (got == 0) break;
      done += (uint64_t)got;
    }
    return done;
  }

  // Skips n bytes; returns how many there were.
  uint64_t Skip(uint64_t n) {
    std::vector<char> scratch(1 << 16);
    uint64_t done = 0;
    while (done < n) {
      const uint64_t got = Read(scratch.data(), std::min<uint64_t>(n - done, scratch.size()));
      if (got == 0) break;
      done += got;
    }
    return done;
  }

 private:
  std::string path_;
  gzFile file_;
};

struct TarEntry {
  std::string name;
  uint64_t size = 0;
  char type = '0';
};

// Octal field (NUL/space padded), or GNU base-256 when the high bit is set.
uint64_t TarNumber(const char* field, size_t width) {
  if ((unsigned char)field[0] & 0x80) {
    uint64_t v = (unsigned char)field[0] & 0x7f;
    for (size_t i = 1; i < width; ++i) v = (v << 8) | (unsigned char)field[i];
    return v;
  }
  uint64_t v = 0;
  for (size_t i = 0; i < width && field[i]; ++i)
    if (field[i] >= '0' && field[i] <= '7') v = v * 8 + (uint64_t)(field[i] - '0');
  return v;
}

std::string TarString(const char* field, size_t width) { return std::string(field, strnlen(field, width)); }

// Reads the next 512-byte header; false at the end-of-archive block or the
// end of the data. Throws on a partial or damaged header.
bool ReadTarHeader(GzipReader& in, const std::string& path, TarEntry& entry) {
  char h[512];
  const uint64_t got = in.Read(h, sizeof h);
  if (got == 0) return false;
  if (got < sizeof h) throw InputError(path + ": truncated archive (partial tar header)");
  if (std::all_of(h, h + 512, [](char c) { return c == 0; })) return false;
  // The checksum sums the header bytes with the checksum field read as spaces.
  unsigned sum = 0;
  for (int i = 0; i < 512; ++i) sum += (i >= 148 && i < 156) ? ' ' : (unsigned char)h[i];
  if (sum != TarNumber(h + 148, 8)) throw InputError(path + ": not a valid tar archive (bad header checksum)");
  entry.name = TarString(h, 100);
  if (std::memcmp(h + 257, "ustar", 5) == 0 && h[345]) entry.name = TarString(h + 345, 155) + "/" + entry.name;
  entry.size = TarNumber(h + 124, 12);
  entry.type = h[156];
  return true;
}

// Reads the members after the current one to the end of the data, so that a
// damaged archive is an error even when the member we need is intact (and
// zlib checks the stream's CRC at its end).
void VerifyRestOfArchive(GzipReader& in, const std::string& path) {
  TarEntry entry;
  while (ReadTarHeader(in, path, entry)) {
    const uint64_t padded = (entry.size + 511) / 512 * 512;
    if (in.Skip(padded) != padded) throw InputError(path + ": truncated archive (" + entry.name + " is cut short)");
  }
  in.Skip(std::numeric_limits<uint64_t>::max());  // trailing zero blocks up to the gzip end
}

// The bytes of the first regular member whose base name is `baseName`.
// Throws if it is absent, bigger than maxSize, or cut short; with
// `verifyArchive`, also if the rest of the archive is damaged.
std::vector<uint8_t> ReadTarMember(const std::string& path, const std::string& baseName, uint64_t maxSize,
                                   bool verifyArchive) {
  GzipReader in(path);
  TarEntry entry;
  std::string longName;  // from a GNU 'L' entry, naming the entry after it
  while (ReadTarHeader(in, path, entry)) {
    const uint64_t padded = (entry.size + 511) / 512 * 512;
    if (entry.type == 'L') {
      std::vector<char> name(entry.size);
      if (in.Read(name.data(), entry.size) != entry.size) break;
      longName = TarString(name.data(), name.size());
      in.Skip(padded - entry.size);
      continue;
    }
    const std::string name = longName.empty() ? entry.name : longName;
    longName.clear();
    const bool regular = entry.type == '0' || entry.type == '\0';
    if (regular && fs::path(name).filename().string() == baseName) {
      if (entry.size > maxSize)
        throw InputError(path + ": " + baseName + " is " + std::to_string(entry.size) + " bytes, expected at most " +
                         std::to_string(maxSize));
      std::vector<uint8_t> data(entry.size);
      if (in.Read(data.data(), entry.size) != entry.size || in.Skip(padded - entry.size) != padded - entry.size)
        throw InputError(path + ": truncated archive (" + baseName + " is cut short)");
      if (verifyArchive) VerifyRestOfArchive(in, path);
      return data;
    }
    if (in.Skip(padded) != padded) break;
  }
  throw InputError(path + ": no " + baseName + " in the archive (truncated, or not an InVesalius project?)");
}

// A parsed Apple XML plist value: a dict, an array or a scalar's text.
struct PlistValue {
  std::string kind;  // dict, array, string, integer, real, true, false, date, data
  std::string text;
  std::vector<std::pair<std::string, PlistValue>> entries;  // dict
  std::vector<PlistValue> items;                            // array

  const PlistValue* Find(const std::string& key) const {
    for (const auto& e : entries)
      if (e.first == key) return &e.second;
    return nullptr;
  }
};

// A small parser for the plist subset InVesalius writes (no attributes on
// values, no CDATA). Enough to read main.plist; not a general XML parser.
class PlistParser {
 public:
  PlistParser(const std::string& xml, std::string where) : xml_(xml), where_(std::move(where)) {}

  PlistValue ParseDocument() {
    bool selfClosing = false;
    std::string tag = NextTag(&selfClosing);
    if (tag == "plist") tag = NextTag(&selfClosing);
    return ParseValue(tag, selfClosing, 0);
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + ": bad plist: " + what); }

  // The next element tag's name ("/name" for a closing tag), skipping text,
  // the XML declaration, DOCTYPE and comments.
  std::string NextTag(bool* selfClosing) {
    for (;;) {
      const size_t open = xml_.find('<', pos_);
      if (open == std::string::npos) Fail("unexpected end of document");
      if (xml_.compare(open, 4, "<!--") == 0) {
        pos_ = SkipPast(open, "-->");
      } else if (xml_.compare(open, 2, "<?") == 0 || xml_.compare(open, 2, "<!") == 0) {
        pos_ = SkipPast(open, ">");
      } else {
        const size_t close = xml_.find('>', open);
        if (close == std::string::npos) Fail("unterminated tag");
        std::string body = xml_.substr(open + 1, close - open - 1);
        *selfClosing = !body.empty() && body.back() == '/';
        if (*selfClosing) body.pop_back();
        pos_ = close + 1;
        return Trim(body.substr(0, body.find_first_of(" \t\r\n")));
      }
    }
  }

  size_t SkipPast(size_t from, const char* end) {
    const size_t at = xml_.find(end, from);
    if (at == std::string::npos) Fail("unterminated markup");
    return at + std::strlen(end);
  }

  // The text up to </name>, with the predefined XML entities decoded.
  std::string ReadText(const std::string& name) {
    const std::string close = "</" + name + ">";
    const size_t at = xml_.find(close, pos_);
    if (at == std::string::npos) Fail("no " + close);
    std::string raw = xml_.substr(pos_, at - pos_), text;
    pos_ = at + close.size();
    static const std::pair<const char*, char> kEntities[] = {
        {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
    for (size_t i = 0; i < raw.size();) {
      bool decoded = false;
      for (const auto& [entity, c] : kEntities)
        if (raw.compare(i, std::strlen(entity), entity) == 0) {
          text += c;
          i += std::strlen(entity);
          decoded = true;
          break;
        }
      if (!decoded) text += raw[i++];
    }
    return text;
  }

  PlistValue ParseValue(const std::string& tag, bool selfClosing, int depth) {
    if (depth > 64) Fail("nested too deeply");
    PlistValue v;
    v.kind = tag;
    bool childSelfClosing = false;
    if (tag == "dict") {
      while (!selfClosing) {
        const std::string keyTag = NextTag(&childSelfClosing);
        if (keyTag == "/dict") break;
        if (keyTag != "key") Fail("expected <key> in <dict>, found <" + keyTag + ">");
        const std::string key = childSelfClosing ? "" : ReadText("key");
        const std::string valueTag = NextTag(&childSelfClosing);
        v.entries.emplace_back(key, ParseValue(valueTag, childSelfClosing, depth + 1));
      }
    } else if (tag == "array") {
      while (!selfClosing) {
        const std::string itemTag = NextTag(&childSelfClosing);
        if (itemTag == "/array") break;
        v.items.push_back(ParseValue(itemTag, childSelfClosing, depth + 1));
      }
    } else if (tag == "true" || tag == "false") {
      v.text = tag;
    } else if (tag == "string" || tag == "integer" || tag == "real" || tag == "date" || tag == "data") {
      if (!selfClosing) v.text = ReadText(tag);
    } else {
      Fail("unexpected <" + tag + ">");
    }
    return v;
  }

  const std::string& xml_;
  std::string where_;
  size_t pos_ = 0;
};

// `n` numbers from a plist array of <integer>/<real>.
std::vector<double> PlistNumbers(const PlistValue* v, size_t n, const std::string& what, const std::string& where) {
  if (!v || v->kind != "array" || v->items.size() != n)
    throw InputError(where + ": '" + what + "' is not an array of " + std::to_string(n) + " numbers");
  std::vector<double> out;
  for (const PlistValue& item : v->items) {
    char* end = nullptr;
    const double x = std::strtod(item.text.c_str(), &end);
    if ((item.kind != "integer" && item.kind != "real") || end == item.text.c_str())
      throw InputError(where + ": '" + what + "' holds a non-number");
    out.push_back(x);
  }
  return out;
}

std::string PlistString(const PlistValue* v, const std::string& what, const std::string& where) {
  if (!v || v->kind != "string" || v->text.empty()) throw InputError(where + ": no '" + what + "' string");
  return v->text;
}

// numpy dtype names as InVesalius writes them.
std::pair<SourceType, int> NumpyType(const std::string& dtype, const std::string& where) {
  static const std::map<std::string, std::pair<SourceType, int>> kTypes = {
      {"int8", {SourceType::Int8, 1}},       {"uint8", {SourceType::UInt8, 1}},
      {"int16", {SourceType::Int16, 2}},     {"uint16", {SourceType::UInt16, 2}},
      {"int32", {SourceType::Int32, 4}},     {"uint32", {SourceType::UInt32, 4}},
      {"int64", {SourceType::Int64, 8}},     {"uint64", {SourceType::UInt64, 8}},
      {"float32", {SourceType::Float32, 4}}, {"float64", {SourceType::Float64, 8}}};
  auto it = kTypes.find(dtype);
  if (it == kTypes.end()) throw InputError(where + ": unsupported matrix dtype '" + dtype + "'");
  return it->second;
}

void LoadInVesalius(const std::string& path, HostVolume& out) {
  const std::vector<uint8_t> plistBytes = ReadTarMember(path, "main.plist", 16u << 20, false);
  const std::string where = path + ": main.plist";
  const PlistValue root = PlistParser(std::string(plistBytes.begin(), plistBytes.end()), where).ParseDocument();
  const PlistValue* matrix = root.Find("matrix");
  if (!matrix || matrix->kind != "dict") throw InputError(where + ": no 'matrix' dict");
  const auto [type, typeSize] = NumpyType(PlistString(matrix->Find("dtype"), "dtype", where), where);
  const std::string dataName = PlistString(matrix->Find("filename"), "filename", where);
  const std::vector<double> shape = PlistNumbers(matrix->Find("shape"), 3, "shape", where);  // z, y, x
  const std::vector<double> spacing = PlistNumbers(root.Find("spacing"), 3, "spacing", where);  // x, y, z

  for (int a = 0; a < 3; ++a) {
    const double n = shape[2 - a];
    if (!(n >= 1 && n <= std::numeric_limits<int>::max() && n == std::floor(n)))
      throw InputError(where + ": bad matrix shape");
    out.dims[a] = (int)n;
  }
  const uint64_t bytes = (uint64_t)out.VoxelCount() * (uint64_t)typeSize;
  const std::vector<uint8_t> raw = ReadTarMember(path, fs::path(dataName).filename().string(), bytes, true);
  if (raw.size() != bytes)
    throw InputError(path + ": " + dataName + " holds " + std::to_string(raw.size()) + " bytes, expected " +
                     std::to_string(bytes) + " for the matrix shape");
  // The .dat is little endian, as is every platform this project builds on.
  StoreVoxels(raw.data(), type, out.VoxelCount(), Rescale{}, out);
  out.indexToWorld = IndexToWorld({0, (out.dims[1] - 1) * spacing[1], 0}, {spacing[0], spacing[1], spacing[2]},
                                  {1, 0, 0, 0, -1, 0, 0, 0, 1});
}

// ---------------------------------------------------------------------------
// 5. Dispatch
// ---------------------------------------------------------------------------

using FileLoader = void (*)(const std::string&, HostVolume&);

struct FormatEntry {
  const char* extension;
  FileLoader load;
};

constexpr FormatEntry kFormats[] = {
    {".nrrd", LoadNrrd},     {".nhdr", LoadNrrd},      {".nii", LoadNifti}, {".nii.gz", LoadNifti},
    {".mha", LoadMetaImage}, {".mhd", LoadMetaImage},  {".vti", LoadVti},   {".vtk", LoadLegacyVtk},
    {".inv3", LoadInVesalius},
};

void LoadVolumeFile(const std::string& path, HostVolume& out) {
  const std::string ext = VolumeExtension(path);
  for (const FormatEntry& f : kFormats)
    if (ext == f.extension) return f.load(path, out);
  std::string known;
  for (const FormatEntry& f : kFormats) known += std::string(known.empty() ? "" : " ") + f.extension;
  throw InputError(path + ": unknown volume format '" + ext + "' (known: " + known + ", or a DICOM folder)");
}

}  // namespace

HostVolume LoadVolume(const std::string& path, const std::string& name, Interpolation interpolation) {
  if (path.empty()) throw InputError("no volume path given");
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path + ": no such file or folder");

  HostVolume volume;
  volume.name = name;
  volume.source = path;
  volume.interpolation = interpolation;
  try {
    if (fs::is_directory(status))
      LoadDicomFolder(path, volume);
    else
      LoadVolumeFile(path, volume);
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw InputError(path + ": not enough memory for the volume (is the header corrupt?)");
  } catch (const std::exception& e) {
    throw InputError(path + ": " + e.what());
  }
  volume.Validate();
  return volume;
}

std::string DefaultVolumePath() { return "/usr/share/doc/invesalius-examples/examples/Cranium.inv3"; }

}  // namespace mmrtm
