// Helpers the volume loader's format files share: small string and number
// helpers, and the conversion of stored voxels (any file type, optional
// rescale) into a HostVolume's native voxel types.
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

namespace mmrtm
{

// ---------------------------------------------------------------------------
// Small helpers
// ---------------------------------------------------------------------------

std::string ToLower(std::string s)
{
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return (char)std::tolower(c); });
  return s;
}

std::string Trim(const std::string& s)
{
  const char* space = " \t\r\n\f\v";
  size_t b = s.find_first_not_of(space);
  if (b == std::string::npos)
    return "";
  return s.substr(b, s.find_last_not_of(space) - b + 1);
}

std::vector<double> ParseNumbers(const std::string& text)
{
  std::vector<double> out;
  std::istringstream in(text);
  std::string token;
  while (in >> token)
  {
    char* end = nullptr;
    double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0')
      break;
    out.push_back(v);
  }
  return out;
}

Vec3d Cross(const Vec3d& a, const Vec3d& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
double Dot(const Vec3d& a, const Vec3d& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

[[noreturn]] void ThrowComponents(const std::string& path, int64_t components)
{
  throw InputError(path + ": has " + std::to_string(components) + " components; a single-component volume is needed");
}

// ---------------------------------------------------------------------------
// Voxel conversion
// ---------------------------------------------------------------------------

namespace
{

// Calls f with the data pointer cast to the C++ type of `type`.
template <typename F>
void WithTypedPointer(SourceType type, const void* data, F&& f)
{
  switch (type)
  {
    case SourceType::Int8:
      f(static_cast<const int8_t*>(data));
      break;
    case SourceType::UInt8:
      f(static_cast<const uint8_t*>(data));
      break;
    case SourceType::Int16:
      f(static_cast<const int16_t*>(data));
      break;
    case SourceType::UInt16:
      f(static_cast<const uint16_t*>(data));
      break;
    case SourceType::Int32:
      f(static_cast<const int32_t*>(data));
      break;
    case SourceType::UInt32:
      f(static_cast<const uint32_t*>(data));
      break;
    case SourceType::Int64:
      f(static_cast<const int64_t*>(data));
      break;
    case SourceType::UInt64:
      f(static_cast<const uint64_t*>(data));
      break;
    case SourceType::Float32:
      f(static_cast<const float*>(data));
      break;
    case SourceType::Float64:
      f(static_cast<const double*>(data));
      break;
  }
}

template <typename T>
ValueStats ScanValues(const T* p, int64_t n, Rescale r)
{
  ValueStats s;
  for (int64_t i = 0; i < n; ++i)
  {
    const double v = (double)p[i] * r.slope + r.intercept;
    if (!(std::isfinite(v) && v == std::floor(v)))
      s.allIntegers = false; // NaN fails too
    s.lo = std::min(s.lo, v);
    s.hi = std::max(s.hi, v);
  }
  return s;
}

} // namespace

ValueStats ScanFloatValues(const float* values, int64_t count)
{
  return ScanValues(values, count, Rescale{});
}

void ValueStats::Add(const ValueStats& other)
{
  allIntegers = allIntegers && other.allIntegers;
  lo = std::min(lo, other.lo);
  hi = std::max(hi, other.hi);
}

VoxelType SmallestExactType(const ValueStats& s)
{
  if (!s.allIntegers)
    return VoxelType::Float32;
  if (s.lo >= 0 && s.hi <= 255)
    return VoxelType::UInt8;
  if (s.lo >= -32768 && s.hi <= 32767)
    return VoxelType::Int16;
  if (s.lo >= 0 && s.hi <= 65535)
    return VoxelType::UInt16;
  return VoxelType::Float32;
}

namespace
{

template <typename Out, typename In>
void ConvertValues(const In* in, int64_t n, Rescale r, uint8_t* outBytes)
{
  Out* out = reinterpret_cast<Out*>(outBytes);
  for (int64_t i = 0; i < n; ++i)
    out[i] = static_cast<Out>((double)in[i] * r.slope + r.intercept);
}

} // namespace

std::optional<VoxelType> NativeVoxelType(SourceType t)
{
  switch (t)
  {
    case SourceType::UInt8:
      return VoxelType::UInt8;
    case SourceType::Int16:
      return VoxelType::Int16;
    case SourceType::UInt16:
      return VoxelType::UInt16;
    case SourceType::Float32:
      return VoxelType::Float32;
    default:
      return std::nullopt;
  }
}

void StoreVoxels(const void* data, SourceType type, int64_t count, Rescale rescale, HostVolume& out)
{
  if (const auto native = NativeVoxelType(type); native && rescale.IsIdentity())
  {
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
  uint8_t* converted = out.voxels.MutableData();
  WithTypedPointer(type, data,
    [&](auto* p)
    {
      switch (target)
      {
        case VoxelType::UInt8:
          ConvertValues<uint8_t>(p, count, rescale, converted);
          break;
        case VoxelType::Int16:
          ConvertValues<int16_t>(p, count, rescale, converted);
          break;
        case VoxelType::UInt16:
          ConvertValues<uint16_t>(p, count, rescale, converted);
          break;
        case VoxelType::Float32:
          ConvertValues<float>(p, count, rescale, converted);
          break;
      }
    });
}

void ReverseRuns(HostVolume& v, int64_t runVoxels, int64_t runsPerBlock)
{
  const size_t run = (size_t)runVoxels * VoxelTypeSize(v.type), block = run * (size_t)runsPerBlock;
  if (run == 0 || block == 0)
    return;
  uint8_t* bytes = v.voxels.MutableData();
  for (size_t b = 0; b + block <= v.voxels.size(); b += block)
    for (int64_t lo = 0, hi = runsPerBlock - 1; lo < hi; ++lo, --hi)
      std::swap_ranges(bytes + b + lo * run, bytes + b + (lo + 1) * run, bytes + b + hi * run);
}

bool IsUncompressedTransferSyntax(const std::string& uid)
{
  return uid == "1.2.840.10008.1.2" || uid == "1.2.840.10008.1.2.1" || uid == "1.2.840.10008.1.2.2";
}

// ---------------------------------------------------------------------------
// Memory and warnings
// ---------------------------------------------------------------------------

namespace
{

// MemAvailable from /proc/meminfo (what can be allocated without swapping);
// 0 if unknown.
double AvailableMemoryBytes()
{
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit)
    if (key == "MemAvailable:")
      return kib * 1024.0;
  return 0.0;
}

std::string HumanBytes(double bytes)
{
  const char* units[] = { "bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB" };
  int u = 0;
  while (bytes >= 1024.0 && u < 6)
  {
    bytes /= 1024.0;
    ++u;
  }
  char text[32];
  std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
  return text;
}

} // namespace

void CheckMemoryAvailable(const std::string& path, double bytes, const std::string& what)
{
  const double available = AvailableMemoryBytes();
  if (available > 0 && bytes > available)
    throw InputError(path + ": " + what + " needs " + HumanBytes(bytes) + " but this machine has " +
      HumanBytes(available) + " of memory available; nothing was allocated");
}

std::optional<long long> IntegerWord(const std::string& word)
{
  char* end = nullptr;
  const long long v = std::strtoll(word.c_str(), &end, 10);
  if (word.empty() || *end != '\0' || std::llabs(v) > std::numeric_limits<int>::max())
    return std::nullopt;
  return v;
}

std::vector<int64_t> PositiveIntegers(const std::string& path, const std::string& what, const std::string& value)
{
  std::vector<int64_t> numbers;
  std::istringstream words(value);
  for (std::string w; words >> w;)
  {
    const std::optional<long long> v = IntegerWord(w);
    if (!v || *v < 1)
      throw InputError(path + ": " + what + " must be positive integers: " + value);
    numbers.push_back(*v);
  }
  return numbers;
}

void CheckFileNamePattern(const std::string& path, const std::string& what, const std::string& pattern)
{
  int conversions = 0;
  for (size_t i = 0; i < pattern.size(); ++i)
  {
    if (pattern[i] != '%')
      continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%')
    { // a literal %
      ++i;
      continue;
    }
    size_t j = i + 1;
    while (j < pattern.size() && (std::isdigit((unsigned char)pattern[j]) || pattern[j] == '-'))
      ++j;
    if (j >= pattern.size() || (pattern[j] != 'd' && pattern[j] != 'i'))
      throw InputError(
        path + ": " + what + ": a file-name pattern may hold only integer conversions such as %d or %03d");
    ++conversions;
    i = j;
  }
  if (conversions != 1)
    throw InputError(path + ": " + what + ": a file-name pattern needs exactly one %d");
}

void CheckDeclaredVoxelBytes(const std::string& path, double declaredBytes, double count, double fileBytes,
  DataEncoding encoding, const std::string& dataFile)
{
  constexpr double kMaxDeflateRatio = 1032.0; // zlib's limit for any input
  const double needed = encoding == DataEncoding::Raw ? declaredBytes
    : encoding == DataEncoding::Compressed            ? declaredBytes / kMaxDeflateRatio
                                                      : count;
  if (!(needed <= fileBytes))
  {
    // Exact counts where the rounded ones would read the same.
    const bool close = HumanBytes(declaredBytes) == HumanBytes(fileBytes);
    const auto bytes = [&](double b) { return close ? std::to_string((long long)b) + " bytes" : HumanBytes(b); };
    throw InputError(path + ": the header promises " + bytes(declaredBytes) + " of voxels but " +
      (dataFile.empty() ? "the file" : "its data file '" + dataFile + "'") + " holds " + bytes(fileBytes) +
      (encoding == DataEncoding::Compressed ? " of compressed data" : "") +
      " (truncated, or a corrupt header); nothing was allocated");
  }
  CheckMemoryAvailable(path, 2.0 * declaredBytes, "the voxels");
}

void Warn(const VolumeLoadOptions& options, const std::string& message)
{
  if (options.warn)
    options.warn(message);
  else
    std::fprintf(stderr, "warning: %s\n", message.c_str());
}

} // namespace mmrtm
