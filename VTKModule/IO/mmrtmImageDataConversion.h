// A vtkImageData (one component of its scalars) as a HostVolume: for the VTK
// mapper, which receives images from a pipeline rather than files. Voxel
// types follow the loader's rules (mmrtmVolumeLoader.h).
#pragma once

#include <string>

#include "host_volume.h"

class vtkDataArray;
class vtkImageData;

namespace mmrtm
{

// Component `component` of `scalars` (the image's point scalars when null)
// as a HostVolume; its indexToWorld is the image's own geometry (origin,
// spacing, direction, extent). Single-component scalars of a type the tracer
// samples natively (uint8, int16, uint16, float) are read in place: the
// volume's voxels borrow the array's memory and hold a reference to the
// array, and are never written (a float image with NaN voxels is copied
// before they are replaced: HostVolume::ReplaceNanVoxels, counted in
// nanVoxelsReplaced). Other types are converted, and a component of
// interleaved scalars is gathered, into a buffer of the volume's own.
// Throws InputError naming `name` for an image without scalars, a missing
// component, a type it cannot hold or an infinite voxel.
HostVolume ImageDataToHostVolume(
  vtkImageData* image, vtkDataArray* scalars, int component, const std::string& name, Interpolation interpolation);

} // namespace mmrtm
