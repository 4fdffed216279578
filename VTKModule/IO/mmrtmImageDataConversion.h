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

// Copies component `component` of `scalars` (the image's point scalars when
// null) into a HostVolume; its indexToWorld is the image's own geometry
// (origin, spacing, direction, extent); NaN voxels are replaced
// (HostVolume::ReplaceNanVoxels, counted in nanVoxelsReplaced). Throws
// InputError naming `name` for an image without scalars, a missing
// component, a type it cannot hold or an infinite voxel.
HostVolume ImageDataToHostVolume(
  vtkImageData* image, vtkDataArray* scalars, int component, const std::string& name, Interpolation interpolation);

} // namespace mmrtm
