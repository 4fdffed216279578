// NIfTI-1/2 volumes (.nii, .nii.gz) through vtkNIFTIImageReader: voxels with
// the scl_slope/scl_intercept rescale, and the sform (else qform) converted
// from RAS to LPS.
#include "mmrtmVolumeLoaderInternal.h"

#include <cmath>
#include <string>

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNew.h>

namespace mmrtm {

// vtkNIFTIImageReader gives a matrix M (sform, else qform) from VTK data
// coordinates (origin + spacing * index) to NIfTI world, which is RAS. When
// qfac is -1 (or the sform is left-handed and there is no qform) it reverses
// the slice order and adjusts M to match, so M always fits the stored voxels.

namespace {

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

}  // namespace

void LoadNifti(const std::string& path, HostVolume& out, const VolumeLoadOptions& /*options*/) {
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

}  // namespace mmrtm
