// NIfTI-1/2 volumes (.nii, .nii.gz) through vtkNIFTIImageReader: voxels with
// the scl_slope/scl_intercept rescale, and the sform (else qform) converted
// from RAS to LPS.
#include "mmrtmVolumeLoaderInternal.h"

#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNew.h>

namespace mmrtm
{

// vtkNIFTIImageReader gives a matrix M (sform, else qform) from VTK data
// coordinates (origin + spacing * index) to NIfTI world, which is RAS. When
// qfac is -1 (or the sform is left-handed and there is no qform) it reverses
// the slice order and adjusts M to match, so M always fits the stored voxels.

namespace
{

// Index -> LPS world: the sform if there is one, else the qform. With
// neither, NIfTI coordinates are the scaled index (method 1), still in RAS,
// as ITK and nibabel read them.
Affine3 NiftiIndexToWorld(vtkNIFTIImageReader* reader, vtkImageData* image)
{
  vtkMatrix4x4* m = reader->GetSFormMatrix() ? reader->GetSFormMatrix() : reader->GetQFormMatrix();
  vtkNew<vtkMatrix4x4> identity;
  if (!m)
    m = identity;
  const Vec3d rasToLps{ -1, -1, 1 };
  const double* o = image->GetOrigin();
  const double* s = image->GetSpacing();
  const int* e = image->GetExtent();
  Mat3d direction;
  Vec3d origin;
  for (int r = 0; r < 3; ++r)
  {
    double world = m->GetElement(r, 3);
    for (int c = 0; c < 3; ++c)
    {
      direction[3 * r + c] = rasToLps[r] * m->GetElement(r, c);
      world += m->GetElement(r, c) * (o[c] + s[c] * e[2 * c]);
    }
    origin[r] = rasToLps[r] * world;
  }
  return IndexToWorld(origin, { s[0], s[1], s[2] }, direction);
}

// The header's fields, read in either byte order.
class NiftiBytes
{
public:
  NiftiBytes(const unsigned char* bytes, bool swap)
    : bytes_(bytes)
    , swap_(swap)
  {
  }
  template <typename T>
  T At(size_t offset) const
  {
    unsigned char b[sizeof(T)];
    std::memcpy(b, bytes_ + offset, sizeof(T));
    if (swap_)
      for (size_t i = 0; i < sizeof(T) / 2; ++i)
        std::swap(b[i], b[sizeof(T) - 1 - i]);
    T value;
    std::memcpy(&value, b, sizeof(T));
    return value;
  }

private:
  const unsigned char* bytes_;
  bool swap_;
};

// Bytes per voxel of the scalar NIfTI datatypes; 0 for the others (complex,
// RGB, RGBA, 128-bit floats: not a scalar volume).
int NiftiScalarSize(int datatype)
{
  switch (datatype)
  {
    case 2:
    case 256:
      return 1; // uint8, int8
    case 4:
    case 512:
      return 2; // int16, uint16
    case 8:
    case 768:
    case 16:
      return 4; // int32, uint32, float32
    case 64:
    case 1024:
    case 1280:
      return 8; // float64, int64, uint64
    default:
      return 0;
  }
}

// vtkNIFTIImageReader trusts its header: an unknown datatype crashed it
// (SIGBUS in RequestInformation, found by fuzzing) and dimensions that promise
// more voxels than the file holds reach an allocation. So the header is read
// and checked here first: NIfTI-1 or -2, either byte order, through zlib so
// that .nii.gz reads the same.
void CheckNiftiHeader(const std::string& path)
{
  unsigned char bytes[540] = {};
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f)
    throw InputError(path + ": cannot open");
  const int got = gzread(f, bytes, sizeof bytes);
  const bool compressed = !gzdirect(f);
  gzclose(f);
  int32_t headerSize;
  std::memcpy(&headerSize, bytes, 4);
  const bool swap = headerSize != 348 && headerSize != 540;
  const NiftiBytes h(bytes, swap);
  headerSize = h.At<int32_t>(0);
  const bool nifti2 = headerSize == 540;
  if ((headerSize != 348 && headerSize != 540) || got < headerSize)
    throw InputError(path + ": not a NIfTI file (no NIfTI-1 or NIfTI-2 header)");
  const char* magic = reinterpret_cast<const char*>(bytes) + (nifti2 ? 4 : 344);
  if (std::strncmp(magic, nifti2 ? "n+2" : "n+1", 4) != 0)
    throw InputError(path + ": not a single-file NIfTI (its magic is not \"" + std::string(nifti2 ? "n+2" : "n+1") +
      "\"; a .hdr/.img pair is not read)");

  const int datatype = nifti2 ? h.At<int16_t>(12) : h.At<int16_t>(70);
  const int bitpix = nifti2 ? h.At<int16_t>(14) : h.At<int16_t>(72);
  const int size = NiftiScalarSize(datatype);
  if (size == 0)
    throw InputError(path + ": NIfTI datatype " + std::to_string(datatype) +
      " is not a scalar integer or float type (one value per voxel is needed)");
  if (bitpix != 8 * size)
    throw InputError(path + ": NIfTI bitpix " + std::to_string(bitpix) + " does not match datatype " +
      std::to_string(datatype) + " (" + std::to_string(8 * size) + " bits)");
  const int64_t rank = nifti2 ? h.At<int64_t>(16) : h.At<int16_t>(40);
  if (rank < 1 || rank > 7)
    throw InputError(path + ": NIfTI dim[0] is " + std::to_string(rank) + ", not 1 to 7");
  double count = 1;
  for (int a = 1; a <= rank; ++a)
  {
    const int64_t n = nifti2 ? h.At<int64_t>(16 + 8 * a) : h.At<int16_t>(40 + 2 * a);
    if (n < 1)
      throw InputError(path + ": NIfTI dim[" + std::to_string(a) + "] is " + std::to_string(n));
    count *= (double)n;
  }
  const double offset = nifti2 ? (double)h.At<int64_t>(168) : (double)h.At<float>(108);
  if (!(offset >= headerSize + 4) || !(offset < 1e15))
    throw InputError(path + ": NIfTI vox_offset " + std::to_string(offset) + " is not after the header");
  std::error_code ec;
  const double fileBytes = (double)std::filesystem::file_size(path, ec);
  if (ec)
    throw InputError(path + ": cannot read its size (" + ec.message() + ")");
  CheckDeclaredVoxelBytes(path, count * size, count, compressed ? fileBytes : fileBytes - offset,
    compressed ? DataEncoding::Compressed : DataEncoding::Raw);
}

} // namespace

void LoadNifti(const std::string& path, HostVolume& out, const VolumeLoadOptions& options)
{
  CheckNiftiHeader(path);
  vtkNew<vtkNIFTIImageReader> reader;
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path, options.progress);
  if (reader->GetTimeDimension() > 1)
    throw InputError(
      path + ": has " + std::to_string(reader->GetTimeDimension()) + " time points; a single 3D volume is needed");

  // scl_slope == 0 means "no scaling" in the NIfTI standard.
  Rescale rescale;
  const double slope = reader->GetRescaleSlope(), intercept = reader->GetRescaleIntercept();
  if (slope != 0 && std::isfinite(slope) && std::isfinite(intercept))
    rescale = { slope, intercept };
  StoreImageVoxels(image, path, rescale, out);
  out.indexToWorld = NiftiIndexToWorld(reader, image);
}

} // namespace mmrtm
