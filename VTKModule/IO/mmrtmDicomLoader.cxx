// DICOM series without ITK (MMRTM_ENABLE_ITK off; mmrtmItkDicomLoader.cxx is
// the full reader): a folder of uncompressed slice files through
// vtkDICOMImageReader, after checks it does not make itself; voxels stored in
// DICOM order, geometry from ImagePositionPatient and ImageOrientationPatient.
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include <vtkDICOMImageReader.h>
#include <vtkImageData.h>
#include <vtkNew.h>

namespace fs = std::filesystem;

namespace mmrtm
{

// vtkDICOMImageReader reads uncompressed series only, and aborts the process
// on some compressed ones (JPEG 2000), so the transfer syntax of every file is
// checked first. It applies the rescale slope/intercept itself, sorts the
// slices by position along the slice normal (descending) and stores each
// slice bottom row first. We store the voxels in DICOM order instead (rows as
// in the file, slices ascending along the normal, as ITK/GDCM do), so that
// index (0,0,0) is the first pixel of the first slice and its
// ImagePositionPatient is the origin.

namespace
{

// The TransferSyntaxUID (0002,0010) from a Part 10 file's meta header; "" if
// the file has no "DICM" preamble (an old ACR-NEMA file or not DICOM).
std::string ReadDicomTransferSyntax(const std::string& file)
{
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  if (!in.seekg(128) || !in.read(magic, 4) || std::memcmp(magic, "DICM", 4) != 0)
    return "";
  // Group 0002 is always explicit VR little endian.
  for (int element = 0; element < 64; ++element)
  {
    uint8_t tag[8];
    if (!in.read(reinterpret_cast<char*>(tag), 8))
      return "";
    const unsigned group = tag[0] | (tag[1] << 8), elem = tag[2] | (tag[3] << 8);
    if (group != 0x0002)
      return "";
    const std::string vr(reinterpret_cast<char*>(tag + 4), 2);
    uint32_t length = tag[6] | (tag[7] << 8);
    if (vr == "OB" || vr == "OW" || vr == "OF" || vr == "SQ" || vr == "UT" || vr == "UN" || vr == "UC" || vr == "UR" ||
      vr == "OD" || vr == "OL" || vr == "OV")
    {
      uint8_t len32[4];
      if (!in.read(reinterpret_cast<char*>(len32), 4))
        return "";
      length = len32[0] | (len32[1] << 8) | (len32[2] << 16) | ((uint32_t)len32[3] << 24);
    }
    if (length > (1u << 16))
      return "";
    std::string value(length, '\0');
    if (!in.read(&value[0], length))
      return "";
    if (elem == 0x0010)
      return Trim(value.substr(0, value.find('\0')));
  }
  return "";
}

std::string DescribeTransferSyntax(const std::string& uid)
{
  if (uid == "1.2.840.10008.1.2.4.90" || uid == "1.2.840.10008.1.2.4.91")
    return "JPEG 2000 compressed";
  if (uid.rfind("1.2.840.10008.1.2.4.20", 0) == 0)
    return "High-Throughput JPEG 2000 compressed";
  if (uid == "1.2.840.10008.1.2.4.80" || uid == "1.2.840.10008.1.2.4.81")
    return "JPEG-LS compressed";
  if (uid.rfind("1.2.840.10008.1.2.4.", 0) == 0)
    return "JPEG compressed";
  if (uid == "1.2.840.10008.1.2.5")
    return "RLE compressed";
  if (uid == "1.2.840.10008.1.2.1.99")
    return "deflate compressed";
  return "compressed or unknown transfer syntax";
}

// The regular files of a folder, sorted; DICOMDIR (a CD's index, no image)
// is left out.
std::vector<std::string> ListFiles(const std::string& folder)
{
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file(ec) && ToLower(entry.path().filename().string()) != "dicomdir")
      files.push_back(entry.path().string());
  if (ec)
    throw InputError(folder + ": cannot list the folder: " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

// Throws before vtkDICOMImageReader sees a file it cannot decode. Returns
// how many files are DICOM Part 10 files (with a "DICM" preamble).
int CheckDicomTransferSyntaxes(const std::string& folder, const std::vector<std::string>& files)
{
  int part10 = 0;
  for (const std::string& file : files)
  {
    const std::string problem = CheckDicomElementLengths(file);
    if (!problem.empty())
      throw InputError(folder + ": " + fs::path(file).filename().string() + ": " + problem);
    const std::string uid = ReadDicomTransferSyntax(file);
    if (uid.empty())
      continue;
    ++part10;
    if (!IsUncompressedTransferSyntax(uid))
      throw InputError(folder + ": " + fs::path(file).filename().string() + " is " + DescribeTransferSyntax(uid) +
        " DICOM (transfer syntax " + uid +
        "); it needs the ITK/GDCM reader, which this build lacks (MMRTM_ENABLE_ITK is off, as in the pip wheel)");
  }
  return part10;
}

// vtkDICOMImageReader keeps its sorted file list protected in VTK 9.1; this
// subclass only makes it readable.
class DicomSeriesReader : public vtkDICOMImageReader
{
public:
  static DicomSeriesReader* New()
  {
    auto* reader = new DicomSeriesReader;
    reader->InitializeObjectBase();
    return reader;
  }
  vtkTypeMacro(DicomSeriesReader, vtkDICOMImageReader)
  int SliceFileCount() { return GetNumberOfDICOMFileNames(); }
  std::string SliceFile(int i) { return GetDICOMFileName(i); }
};

// What one slice file's header says about its place and pixel layout.
struct DicomSliceHeader
{
  std::string file;
  Vec3d position;            // ImagePositionPatient, LPS mm
  std::array<double, 6> iop; // ImageOrientationPatient: row direction, column direction
  int width = 0, height = 0, bitsAllocated = 0, components = 0;
};

// Reads one file's header (no pixels).
DicomSliceHeader ReadDicomSliceHeader(const std::string& file)
{
  vtkNew<vtkDICOMImageReader> reader;
  reader->SetFileName(file.c_str());
  ReaderErrors errors(reader);
  reader->UpdateInformation();
  errors.ThrowIfFailed(file);
  DicomSliceHeader h;
  h.file = file;
  const float* p = reader->GetImagePositionPatient();
  const float* o = reader->GetImageOrientationPatient();
  for (int i = 0; i < 3; ++i)
    h.position[i] = p[i];
  for (int i = 0; i < 6; ++i)
    h.iop[i] = o[i];
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
void CheckDicomSlicesMatch(const std::string& folder, const std::vector<DicomSliceHeader>& slices)
{
  const DicomSliceHeader& first = slices.front();
  const uint64_t pixelBytes =
    (uint64_t)first.width * first.height * std::max(first.components, 1) * ((first.bitsAllocated + 7) / 8);
  for (const DicomSliceHeader& s : slices)
  {
    const std::string name = fs::path(s.file).filename().string();
    if (s.width != first.width || s.height != first.height || s.bitsAllocated != first.bitsAllocated ||
      s.components != first.components)
      throw InputError(folder + ": " + name + " is " + std::to_string(s.width) + " x " + std::to_string(s.height) +
        " with " + std::to_string(s.bitsAllocated) + "-bit pixels, unlike the first slice (" +
        std::to_string(first.width) + " x " + std::to_string(first.height) + ", " +
        std::to_string(first.bitsAllocated) + "-bit)");
    std::error_code ec;
    if (fs::file_size(s.file, ec) < pixelBytes + 132) // 128-byte preamble + "DICM"
      throw InputError(folder + ": " + name + " is too short for its pixel data (truncated?)");
  }
}

// The world offset from one slice to the next, from the first and last
// ImagePositionPatient. Throws when the slices are not evenly spaced along
// it (a missing slice, mixed series): the volume grid would misplace them.
Vec3d DicomSliceStep(const std::string& folder, const std::vector<DicomSliceHeader>& slices, double thickness)
{
  const int n = (int)slices.size();
  const Vec3d row{ slices[0].iop[0], slices[0].iop[1], slices[0].iop[2] };
  const Vec3d column{ slices[0].iop[3], slices[0].iop[4], slices[0].iop[5] };
  Vec3d step;
  if (n == 1)
  { // one slice: its thickness along the normal
    const Vec3d normal = Cross(row, column);
    for (int r = 0; r < 3; ++r)
      step[r] = normal[r] * thickness;
    return step;
  }
  for (int r = 0; r < 3; ++r)
    step[r] = (slices[n - 1].position[r] - slices[0].position[r]) / (n - 1);
  const double length = std::sqrt(Dot(step, step));
  if (!(length > 0))
    throw InputError(folder + ": all slices share one position (not a volume series?)");
  for (int i = 0; i < n; ++i)
  {
    Vec3d offset;
    for (int r = 0; r < 3; ++r)
      offset[r] = slices[i].position[r] - (slices[0].position[r] + i * step[r]);
    if (std::sqrt(Dot(offset, offset)) > 0.1 * length)
      throw InputError(folder + ": slices are not evenly spaced (" + fs::path(slices[i].file).filename().string() +
        " is " + std::to_string(std::sqrt(Dot(offset, offset))) + " mm off the regular grid; a missing slice?)");
  }
  return step;
}

} // namespace

void LoadDicomFolder(const std::string& folder, HostVolume& out, const VolumeLoadOptions& options)
{
  if (!options.series.empty())
    throw InputError(folder +
      ": choosing a series needs the ITK/GDCM reader, which this build lacks (MMRTM_ENABLE_ITK is off, as in the pip "
      "wheel)");
  const std::vector<std::string> files = ListFiles(folder);
  if (files.empty())
    throw InputError(folder + ": the folder holds no files (expected the DICOM files of one series)");
  const int part10Files = CheckDicomTransferSyntaxes(folder, files);

  vtkNew<DicomSeriesReader> reader;
  reader->SetDirectoryName(folder.c_str());
  {
    ReaderErrors errors(reader);
    reader->UpdateInformation();
    if (reader->SliceFileCount() == 0)
      throw InputError(folder + ": the folder holds no DICOM files");
    errors.ThrowIfFailed(folder);
  }
  // The reader keeps the first series and drops files it cannot place.
  const int n = reader->SliceFileCount();
  if (part10Files > n)
    throw InputError(folder + ": holds " + std::to_string(part10Files) + " DICOM files but only " + std::to_string(n) +
      " form the series (a damaged file, or more than one series?)");
  std::vector<DicomSliceHeader> slices;
  for (int i = 0; i < n; ++i)
    slices.push_back(ReadDicomSliceHeader(reader->SliceFile(i)));
  CheckDicomSlicesMatch(folder, slices);

  vtkImageData* image = RunReader(reader, folder, options.progress);
  StoreImageVoxels(image, folder, Rescale{}, out); // the reader has rescaled already
  if (out.dims[2] != n || out.dims[0] != slices[0].width || out.dims[1] != slices[0].height)
    throw InputError(folder + ": the DICOM reader returned an unexpected volume size");

  // Slices in the reader's order (descending along the normal) -> ascending.
  Vec3d step = DicomSliceStep(folder, slices, image->GetSpacing()[2]);
  const Vec3d row{ slices[0].iop[0], slices[0].iop[1], slices[0].iop[2] };
  const Vec3d column{ slices[0].iop[3], slices[0].iop[4], slices[0].iop[5] };
  const bool reverseSlices = Dot(step, Cross(row, column)) < 0;
  Vec3d origin = slices[0].position;
  if (reverseSlices)
  {
    origin = slices[n - 1].position;
    for (double& v : step)
      v = -v;
  }
  ReverseRuns(out, out.dims[0], out.dims[1]); // rows back to file order (top row first)
  if (reverseSlices)
    ReverseRuns(out, (int64_t)out.dims[0] * out.dims[1], out.dims[2]);

  // PixelSpacing is (row spacing, column spacing): the first value is the
  // distance between rows (y), the second between columns (x); the reader
  // keeps them in that order as its x and y spacing.
  const double dx = image->GetSpacing()[1], dy = image->GetSpacing()[0];
  const double dz = std::sqrt(Dot(step, step));
  // A gantry tilt makes `step` oblique to the normal; keeping the real step
  // (a sheared grid) puts every slice where its ImagePositionPatient says.
  Mat3d direction;
  for (int r = 0; r < 3; ++r)
  {
    direction[3 * r + 0] = row[r];
    direction[3 * r + 1] = column[r];
    direction[3 * r + 2] = step[r] / dz;
  }
  out.indexToWorld = IndexToWorld(origin, { dx, dy, dz }, direction);
}

bool DicomDecodesCompressedSyntaxes()
{
  return false;
}

std::vector<DicomSeriesSummary> ListDicomSeries(const std::string& folder)
{
  throw InputError(folder +
    ": listing DICOM series needs the ITK/GDCM reader, which this build lacks (MMRTM_ENABLE_ITK is off, as in the pip "
    "wheel)");
}

} // namespace mmrtm
