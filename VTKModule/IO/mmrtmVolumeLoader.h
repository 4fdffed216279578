// One volume loader for every application: reads a volume file or a DICOM
// folder into a HostVolume (native voxels + index-to-world geometry).
//
// World space is LPS in millimetres (the DICOM/ITK convention). Voxels are
// stored x fastest; HostVolume::indexToWorld maps voxel index (i, j, k) to
// world. VTK is used behind this interface only: no VTK header here.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "host_volume.h"

namespace mmrtm
{

// Loads a volume file or a DICOM folder into a HostVolume named `name`.
//
// Formats, chosen by extension (case-insensitive):
//   .nrrd .nhdr      NRRD (space directions / space origin honoured)
//   .nii .nii.gz     NIfTI-1/2 (sform, else qform; RAS converted to LPS)
//   .mha .mhd        MetaImage (TransformMatrix, Offset, ElementSpacing)
//   .vti             VTK XML image data (origin, spacing, direction)
//   .vtk             VTK legacy STRUCTURED_POINTS (origin, spacing)
//   .inv3            InVesalius project (identity orientation, origin 0)
//   a folder         DICOM series, through ITK/GDCM (every transfer syntax
//                    GDCM decodes, JPEG 2000 included); without ITK
//                    (MMRTM_ENABLE_ITK off) vtkDICOMImageReader, uncompressed only
//
// DICOM (Documentation/dicom.md): the largest series in the folder is read
// unless VolumeLoadOptions::series names one; rescale slope/intercept are
// applied (Hounsfield units for CT); orientation and origin go into
// indexToWorld; a gantry tilt is kept as a shear of the grid; slices spaced
// unevenly (a missing slice) are resampled onto a regular grid, with a warning.
//
// Voxel types: uint8, int16, uint16 and float32 are kept as they are. Other
// types, and volumes with a rescale slope/intercept, become the smallest of
// uint8 / int16 / uint16 that holds every value exactly when all values are
// integers, else float32.
//
// Throws InputError, whose message names the file and the problem, for a
// missing path, an unknown extension, an unreadable, corrupt or truncated
// file, an empty volume, more than one component per voxel, infinite
// voxels and folders without readable DICOM files. NaN voxels are read as
// the volume's least value (HostVolume::ReplaceNanVoxels; counted in
// nanVoxelsReplaced for the caller's warning).
HostVolume LoadVolume(
  const std::string& path, const std::string& name = "scalars", Interpolation interpolation = Interpolation::Trilinear);

struct VolumeLoadOptions
{
  Interpolation interpolation = Interpolation::Trilinear;
  // DICOM folders: the SeriesInstanceUID or the SeriesDescription of the
  // series to read; empty reads the series with the most slices.
  std::string series;
  // Receives each warning (one line, naming the file); null prints them to
  // stderr as "warning: ...".
  std::function<void(const std::string&)> warn;
  // Receives the fraction of the voxels read so far (0 to 1), on the
  // calling thread, where the format's reader can tell (raw NRRD, DICOM
  // slices, VTK's readers); null reports nothing.
  std::function<void(double)> progress;
};

HostVolume LoadVolume(const std::string& path, const std::string& name, const VolumeLoadOptions& options);

// One DICOM series of a folder, as ListDicomSeries reports it.
struct DicomSeriesSummary
{
  std::string uid, description, modality;
  int slices = 0;
  int rows = 0, columns = 0;
};

// The image series of a DICOM folder, most slices first. Throws InputError
// for a missing folder or one with no DICOM image file.
std::vector<DicomSeriesSummary> ListDicomSeries(const std::string& folder);

// Whether DICOM folders are read through ITK/GDCM (compressed transfer
// syntaxes such as JPEG 2000 included) rather than vtkDICOMImageReader
// (uncompressed only).
bool DicomDecodesCompressedSyntaxes();

// The default input: InVesalius's Cranium.inv3 from Debian's
// invesalius-examples package.
std::string DefaultVolumePath();

} // namespace mmrtm
