// DICOM series through ITK and GDCM: every transfer syntax GDCM decodes
// (JPEG 2000 included), series chosen by UID or description, rescale to
// modality units (Hounsfield for CT), orientation and origin in the world
// matrix, gantry tilt kept as a shear, uneven slice spacing resampled.
//
// The headers of every file are read first with gdcm::Scanner (fast, no
// pixels), so that the series can be listed, sorted and checked before any
// voxel is allocated; the pixels of each slice are then decoded with ITK's
// GDCMImageIO, one file at a time, so that a damaged file is named.
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include <gdcmDirectory.h>
#include <gdcmScanner.h>
#include <gdcmTag.h>
#include <gdcmTrace.h>
#include <itkGDCMImageIO.h>
#include <itkImage.h>
#include <itkImageFileReader.h>

namespace fs = std::filesystem;

namespace mmrtm
{
namespace
{

const gdcm::Tag kSeriesUid(0x0020, 0x000e), kSeriesDescription(0x0008, 0x103e), kModality(0x0008, 0x0060),
  kPosition(0x0020, 0x0032), kOrientation(0x0020, 0x0037), kPixelSpacing(0x0028, 0x0030), kRows(0x0028, 0x0010),
  kColumns(0x0028, 0x0011), kFrames(0x0028, 0x0008), kSamplesPerPixel(0x0028, 0x0002), kGantryTilt(0x0018, 0x1120),
  kBitsAllocated(0x0028, 0x0100), kTransferSyntax(0x0002, 0x0010);

// What one file's header says; the pixels are read later.
struct SliceHeader
{
  std::string file;
  std::string uid, description, modality;
  std::string transferSyntax;
  int rows = 0, columns = 0, frames = 1, samples = 1, bitsAllocated = 16;
  std::vector<double> position, orientation, pixelSpacing;
  double gantryTilt = 0.0;
  double along = 0.0; // position along the slice normal
};

std::string FileName(const std::string& path)
{
  return fs::path(path).filename().string();
}

std::string Str(double v, const char* format = "%.4g")
{
  char text[32];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

// DICOM multi-valued strings: "a\b\c", padded with spaces or NULs.
std::vector<double> Numbers(const char* value)
{
  std::string text = value ? value : "";
  std::replace(text.begin(), text.end(), '\\', ' ');
  std::replace(text.begin(), text.end(), '\0', ' ');
  return ParseNumbers(text);
}

std::string Text(const char* value)
{
  std::string text = value ? value : "";
  return Trim(text.substr(0, text.find('\0')));
}

// The header of every DICOM image file in the folder (not recursive).
std::vector<SliceHeader> ScanFolder(const std::string& folder)
{
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw InputError(folder + ": not a folder");
  gdcm::Directory directory;
  const unsigned count = directory.Load(folder, false);
  if (count == 0)
    throw InputError(folder + ": the folder holds no files (expected the DICOM files of a series)");

  for (const std::string& file : directory.GetFilenames())
  {
    const std::string problem = CheckDicomElementLengths(file);
    if (!problem.empty())
      throw InputError(folder + ": " + FileName(file) + ": " + problem);
  }
  gdcm::Scanner scanner;
  for (const gdcm::Tag& t : { kSeriesUid, kSeriesDescription, kModality, kPosition, kOrientation, kPixelSpacing, kRows,
         kColumns, kFrames, kSamplesPerPixel, kGantryTilt, kBitsAllocated, kTransferSyntax })
    scanner.AddTag(t);
  if (!scanner.Scan(directory.GetFilenames()))
    throw InputError(folder + ": cannot scan the folder's files");

  std::vector<SliceHeader> slices;
  for (const std::string& file : directory.GetFilenames())
  {
    if (!scanner.IsKey(file.c_str()))
      continue; // not DICOM
    SliceHeader h;
    h.file = file;
    h.uid = Text(scanner.GetValue(file.c_str(), kSeriesUid));
    h.description = Text(scanner.GetValue(file.c_str(), kSeriesDescription));
    h.modality = Text(scanner.GetValue(file.c_str(), kModality));
    const std::vector<double> rows = Numbers(scanner.GetValue(file.c_str(), kRows)),
                              columns = Numbers(scanner.GetValue(file.c_str(), kColumns)),
                              frames = Numbers(scanner.GetValue(file.c_str(), kFrames)),
                              samples = Numbers(scanner.GetValue(file.c_str(), kSamplesPerPixel)),
                              tilt = Numbers(scanner.GetValue(file.c_str(), kGantryTilt));
    if (rows.empty() || columns.empty())
      continue; // no image (a report, a structure set, DICOMDIR)
    h.rows = (int)rows[0];
    h.columns = (int)columns[0];
    if (!frames.empty())
      h.frames = (int)frames[0];
    if (!samples.empty())
      h.samples = (int)samples[0];
    if (!tilt.empty())
      h.gantryTilt = tilt[0];
    const std::vector<double> bits = Numbers(scanner.GetValue(file.c_str(), kBitsAllocated));
    if (!bits.empty())
      h.bitsAllocated = (int)bits[0];
    h.transferSyntax = Text(scanner.GetValue(file.c_str(), kTransferSyntax));
    h.position = Numbers(scanner.GetValue(file.c_str(), kPosition));
    h.orientation = Numbers(scanner.GetValue(file.c_str(), kOrientation));
    h.pixelSpacing = Numbers(scanner.GetValue(file.c_str(), kPixelSpacing));
    slices.push_back(std::move(h));
  }
  if (slices.empty())
    throw InputError(folder + ": none of its " + std::to_string(count) + " file(s) is a DICOM image");
  return slices;
}

// Groups the slices by SeriesInstanceUID, most slices first.
std::vector<std::vector<SliceHeader>> GroupSeries(std::vector<SliceHeader> slices)
{
  std::map<std::string, std::vector<SliceHeader>> byUid;
  for (SliceHeader& s : slices)
    byUid[s.uid].push_back(std::move(s));
  std::vector<std::vector<SliceHeader>> series;
  for (auto& [uid, list] : byUid)
    series.push_back(std::move(list));
  std::stable_sort(series.begin(), series.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return series;
}

DicomSeriesSummary Summarize(const std::vector<SliceHeader>& series)
{
  const SliceHeader& s = series.front();
  return { s.uid, s.description, s.modality, (int)series.size(), s.rows, s.columns };
}

std::string Describe(const DicomSeriesSummary& s)
{
  return (s.uid.empty() ? std::string("(no SeriesInstanceUID)") : s.uid) + " (" + std::to_string(s.slices) +
    " slice(s) of " + std::to_string(s.columns) + " x " + std::to_string(s.rows) +
    (s.description.empty() ? "" : ", \"" + s.description + "\"") + (s.modality.empty() ? "" : ", " + s.modality) + ")";
}

std::string DescribeAll(const std::vector<std::vector<SliceHeader>>& series)
{
  std::string list;
  for (const auto& s : series)
    list += "\n  " + Describe(Summarize(s));
  return list;
}

// The series named by `selector` (UID, else description, case-insensitive),
// or the largest one when the selector is empty.
const std::vector<SliceHeader>& ChooseSeries(
  const std::string& folder, const std::vector<std::vector<SliceHeader>>& series, const VolumeLoadOptions& options)
{
  if (options.series.empty())
  {
    if (series.size() > 1)
      Warn(options,
        folder + " holds " + std::to_string(series.size()) + " series; reading the largest, " +
          Describe(Summarize(series[0])) + ". Choose another by its UID or description:" + DescribeAll(series));
    return series[0];
  }
  for (const auto& s : series)
    if (s.front().uid == options.series)
      return s;
  const std::vector<SliceHeader>* match = nullptr;
  for (const auto& s : series)
    if (ToLower(s.front().description) == ToLower(options.series))
    {
      if (match)
        throw InputError(folder + ": more than one series is described as \"" + options.series +
          "\"; choose one by its UID:" + DescribeAll(series));
      match = &s;
    }
  if (!match)
    throw InputError(folder + ": no series with the UID or description \"" + options.series +
      "\"; the folder holds:" + DescribeAll(series));
  return *match;
}

Vec3d Vec(const std::vector<double>& v, size_t first)
{
  return { v[first], v[first + 1], v[first + 2] };
}

double Norm(const Vec3d& v)
{
  return std::sqrt(Dot(v, v));
}

// Every slice must have the same size, pixel spacing and orientation, and a
// position: the grid is built from them.
void CheckSlicesAgree(const std::string& folder, const std::vector<SliceHeader>& slices)
{
  const SliceHeader& first = slices.front();
  for (const SliceHeader& s : slices)
  {
    const std::string where = folder + ": " + FileName(s.file);
    if (s.frames > 1)
      throw InputError(where + " holds " + std::to_string(s.frames) +
        " frames; multi-frame DICOM files are not supported (one slice per file)");
    if (s.samples != 1)
      throw InputError(
        where + " has " + std::to_string(s.samples) + " samples per pixel (colour); only greyscale series are volumes");
    if (s.position.size() != 3)
      throw InputError(where + " has no ImagePositionPatient: its slice cannot be placed");
    if (s.orientation.size() != 6)
      throw InputError(where + " has no ImageOrientationPatient");
    if (s.pixelSpacing.size() != 2 || !(s.pixelSpacing[0] > 0) || !(s.pixelSpacing[1] > 0))
      throw InputError(where + " has no valid PixelSpacing");
    if (s.rows != first.rows || s.columns != first.columns)
      throw InputError(where + " is " + std::to_string(s.columns) + " x " + std::to_string(s.rows) + ", but " +
        FileName(first.file) + " is " + std::to_string(first.columns) + " x " + std::to_string(first.rows) +
        ": the slices of a series must have one size");
    for (int a = 0; a < 2; ++a)
      if (std::abs(s.pixelSpacing[a] - first.pixelSpacing[a]) > 1e-4 * first.pixelSpacing[a])
        throw InputError(where + " has PixelSpacing " + Str(s.pixelSpacing[0]) + "\\" + Str(s.pixelSpacing[1]) +
          " but " + FileName(first.file) + " has " + Str(first.pixelSpacing[0]) + "\\" + Str(first.pixelSpacing[1]) +
          ": inconsistent pixel spacing within the series");
    for (int a = 0; a < 6; ++a)
      if (std::abs(s.orientation[a] - first.orientation[a]) > 1e-4)
        throw InputError(where + " has another ImageOrientationPatient than " + FileName(first.file) +
          ": the slices of a series must be parallel");
  }
}

// Sorts the slices along the normal and checks that they lie on one line
// (a tilt moves each slice sideways by the same amount) with distinct positions.
void SortSlices(const std::string& folder, std::vector<SliceHeader>& slices, const Vec3d& normal)
{
  for (SliceHeader& s : slices)
    s.along = Dot(Vec(s.position, 0), normal);
  std::sort(slices.begin(), slices.end(), [](const SliceHeader& a, const SliceHeader& b) { return a.along < b.along; });
  for (size_t i = 1; i < slices.size(); ++i)
    if (slices[i].along - slices[i - 1].along < 1e-3)
      throw InputError(folder + ": " + FileName(slices[i - 1].file) + " and " + FileName(slices[i].file) +
        " lie at the same position (" + Str(slices[i].along) +
        " mm along the normal): two acquisitions in one series, or a duplicated file");
}

// The slice positions along the normal, relative to the first slice.
std::vector<double> Offsets(const std::vector<SliceHeader>& slices)
{
  std::vector<double> d;
  for (const SliceHeader& s : slices)
    d.push_back(s.along - slices.front().along);
  return d;
}

double MedianGap(const std::vector<double>& d)
{
  std::vector<double> gaps;
  for (size_t i = 1; i < d.size(); ++i)
    gaps.push_back(d[i] - d[i - 1]);
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

// Decodes one slice (rescaled to modality units) into `dst` (rows x columns floats).
void ReadSlicePixels(const std::string& folder, const SliceHeader& s, float* dst)
{
  // GDCM pads a cut-short uncompressed file with zeros without a word; a file
  // too small for its pixels is damaged.
  std::error_code ec;
  const double pixelBytes = (double)s.rows * s.columns * ((s.bitsAllocated + 7) / 8);
  // (No transfer syntax: an old file without a meta header, uncompressed.)
  const bool uncompressed = s.transferSyntax.empty() || IsUncompressedTransferSyntax(s.transferSyntax);
  if (uncompressed && (double)fs::file_size(s.file, ec) < pixelBytes)
    throw InputError(folder + ": " + FileName(s.file) + " is " + std::to_string(fs::file_size(s.file, ec)) +
      " bytes, too short for its " + std::to_string((long long)pixelBytes) + " bytes of pixel data (truncated?)");
  using Image = itk::Image<float, 3>;
  auto io = itk::GDCMImageIO::New();
  auto reader = itk::ImageFileReader<Image>::New();
  reader->SetImageIO(io);
  reader->SetFileName(s.file);
  try
  {
    reader->Update();
  }
  catch (const itk::ExceptionObject& e)
  {
    throw InputError(folder + ": " + FileName(s.file) +
      ": cannot decode its pixel data (truncated or corrupt?): " + Trim(e.GetDescription()));
  }
  const Image* image = reader->GetOutput();
  const auto size = image->GetLargestPossibleRegion().GetSize();
  if ((int)size[0] != s.columns || (int)size[1] != s.rows || size[2] != 1)
    throw InputError(folder + ": " + FileName(s.file) + ": decoded " + std::to_string(size[0]) + " x " +
      std::to_string(size[1]) + " x " + std::to_string(size[2]) + " pixels, header says " + std::to_string(s.columns) +
      " x " + std::to_string(s.rows));
  std::copy(image->GetBufferPointer(), image->GetBufferPointer() + (size_t)s.rows * s.columns, dst);
}

// The slices decoded one at a time into a SliceStack: as they are when they
// are evenly spaced; else resampled onto `count` slices `spacing` apart by
// linear interpolation between the two slices (at offsets d) around each,
// so that only those two are held as floats. Integer slices stay integer
// (rounded), so CT keeps int16.
void StackSlices(const std::string& folder, const std::vector<SliceHeader>& slices, const std::vector<double>& d,
  int count, double spacing, bool uneven, int64_t sliceVoxels, SliceStack& stack, const VolumeLoadOptions& options)
{
  struct Decoded
  {
    int index = -1;
    std::vector<float> values;
    ValueStats stats;
  };
  Decoded held[2];
  // Slice k, decoded unless one of the two held slices is k (`keep` is not
  // overwritten).
  auto decode = [&](int k, const Decoded* keep) -> const Decoded&
  {
    for (const Decoded& h : held)
      if (h.index == k)
        return h;
    Decoded& slot = &held[0] == keep ? held[1] : held[0];
    slot.values.resize((size_t)sliceVoxels);
    ReadSlicePixels(folder, slices[k], slot.values.data());
    slot.stats = ScanFloatValues(slot.values.data(), sliceVoxels);
    slot.index = k;
    return slot;
  };
  std::vector<float> resampled(uneven ? (size_t)sliceVoxels : 0);
  size_t k = 0;
  for (int j = 0; j < count; ++j)
  {
    if (!uneven)
    {
      const Decoded& slice = decode(j, nullptr);
      stack.Put(j, slice.values.data(), slice.stats);
    }
    else
    {
      const double t = std::min(j * spacing, d.back());
      while (k + 2 < d.size() && d[k + 1] < t)
        ++k;
      const float w = (float)std::clamp((t - d[k]) / (d[k + 1] - d[k]), 0.0, 1.0);
      const Decoded& a = decode((int)k, nullptr);
      const Decoded& b = decode((int)k + 1, &a);
      const bool integers = a.stats.allIntegers && b.stats.allIntegers;
      for (int64_t i = 0; i < sliceVoxels; ++i)
      {
        const float v = a.values[i] + w * (b.values[i] - a.values[i]);
        resampled[i] = integers ? std::nearbyint(v) : v;
      }
      stack.Put(j, resampled.data(), ScanFloatValues(resampled.data(), sliceVoxels));
    }
    if (options.progress)
      options.progress((j + 1.0) / count);
  }
}

} // namespace

bool DicomDecodesCompressedSyntaxes()
{
  return true;
}

std::vector<DicomSeriesSummary> ListDicomSeries(const std::string& folder)
{
  gdcm::Trace::WarningOff();
  std::vector<DicomSeriesSummary> list;
  for (const auto& s : GroupSeries(ScanFolder(folder)))
    list.push_back(Summarize(s));
  return list;
}

void LoadDicomFolder(const std::string& folder, HostVolume& out, const VolumeLoadOptions& options)
{
  // GDCM warns on stderr about harmless quirks (one FrameOfReferenceUID per
  // file in an anonymised series) and reports decoding errors there too; the
  // checks and InputErrors here say what matters, naming the file.
  gdcm::Trace::WarningOff();
  gdcm::Trace::ErrorOff();
  itk::Object::GlobalWarningDisplayOff();
  const auto series = GroupSeries(ScanFolder(folder));
  std::vector<SliceHeader> slices = ChooseSeries(folder, series, options);
  CheckSlicesAgree(folder, slices);

  // Geometry. DICOM's row direction is that of increasing column index (x),
  // its column direction that of increasing row index (y); PixelSpacing is
  // (distance between rows, distance between columns).
  const SliceHeader& first = slices.front();
  const Vec3d row = Vec(first.orientation, 0), column = Vec(first.orientation, 3);
  Vec3d normal = Cross(row, column);
  const double normalLength = Norm(normal);
  if (!(normalLength > 0.5))
    throw InputError(folder + ": " + FileName(first.file) + " has a degenerate ImageOrientationPatient");
  for (double& v : normal)
    v /= normalLength;
  SortSlices(folder, slices, normal);
  const int n = (int)slices.size();
  const int64_t sliceVoxels = (int64_t)first.rows * first.columns;

  // Slice step: from the first to the last position. With a gantry tilt it
  // is oblique to the normal; keeping it (a sheared grid) puts each slice
  // where its ImagePositionPatient says, without resampling.
  Vec3d step{ 0, 0, 0 };
  std::vector<double> d = Offsets(slices);
  if (n == 1)
  {
    step = normal; // one slice: a unit step along the normal
  }
  else
  {
    for (int r = 0; r < 3; ++r)
      step[r] = (slices[n - 1].position[r] - first.position[r]) / d.back();
    // step is now per mm along the normal; every slice must lie on that line.
    for (const SliceHeader& s : slices)
    {
      const double t = s.along - first.along;
      double off = 0;
      for (int r = 0; r < 3; ++r)
        off += std::pow(s.position[r] - (first.position[r] + t * step[r]), 2);
      if (std::sqrt(off) > 0.1 * std::min(first.pixelSpacing[0], first.pixelSpacing[1]) + 1e-3)
        throw InputError(folder + ": " + FileName(s.file) + " is " + Str(std::sqrt(off)) +
          " mm off the line through the other slices' positions: not one stack of slices");
    }
  }
  const double tiltDegrees = std::acos(std::clamp(Dot(step, normal) / Norm(step), -1.0, 1.0)) * 180.0 / M_PI;
  if (tiltDegrees > 0.01)
    Warn(options,
      folder + ": the slices are tilted by " + Str(tiltDegrees, "%.2f") +
        " degrees (gantry tilt; GantryDetectorTilt says " + Str(first.gantryTilt, "%.2f") +
        "); the volume keeps it as a shear of its grid, so every slice stays where it was acquired");

  // Uneven spacing (a missing slice, a variable-pitch scan): resample onto a
  // regular grid at the median spacing, so that no slice is misplaced.
  int outSlices = n;
  double spacing = 1.0;
  bool uneven = false;
  if (n > 1)
  {
    spacing = MedianGap(d);
    for (int i = 1; i < n; ++i)
      if (std::abs(d[i] - d[i - 1] - spacing) > 0.01 * spacing + 1e-3)
        uneven = true;
    if (uneven)
    {
      outSlices = (int)std::lround(d.back() / spacing) + 1;
      spacing = d.back() / (outSlices - 1);
      double widest = 0;
      int widestAfter = 0;
      for (int i = 1; i < n; ++i)
        if (d[i] - d[i - 1] > widest)
          widest = d[i] - d[i - 1], widestAfter = i - 1;
      Warn(options,
        folder + ": the slices are not evenly spaced (gaps from " + Str(spacing) + " to " + Str(widest) +
          " mm; the widest after " + FileName(slices[widestAfter].file) + ", a missing slice?); resampled onto " +
          std::to_string(outSlices) + " slices " + Str(spacing) +
          " mm apart by linear interpolation between neighbouring slices");
    }
    else
    {
      spacing = d.back() / (n - 1);
    }
  }

  // Pixels: checked against the memory first (float voxels at the most),
  // then decoded into the smallest exact type slice by slice.
  CheckMemoryAvailable(folder, 4.0 * sliceVoxels * outSlices,
    std::to_string(first.columns) + " x " + std::to_string(first.rows) + " x " + std::to_string(outSlices) + " voxels");
  SliceStack stack(sliceVoxels, outSlices);
  StackSlices(folder, slices, d, outSlices, spacing, uneven, sliceVoxels, stack, options);
  out.dims = { first.columns, first.rows, outSlices };
  stack.MoveInto(out);

  // index -> world: columns are the row direction x column spacing, the
  // column direction x row spacing, and the slice step (possibly oblique).
  Affine3 m;
  const Vec3d sliceStep{ step[0] * spacing, step[1] * spacing, step[2] * spacing };
  for (int r = 0; r < 3; ++r)
  {
    m.m[r][0] = (float)(row[r] * first.pixelSpacing[1]);
    m.m[r][1] = (float)(column[r] * first.pixelSpacing[0]);
    m.m[r][2] = (float)sliceStep[r];
    m.m[r][3] = (float)first.position[r];
  }
  out.indexToWorld = m;
}

} // namespace mmrtm
