// Proxy volumes computed from another proxy when a TF reads them (paper
// section 5, DESIGN.md rule 3): gradient magnitude, a smoothed copy and an
// opacity. Each has the grid (dims, indexToWorld) of its source, trilinear
// interpolation, and the smallest voxel type that holds it:
//   - a float32 source gives float32 (gradient magnitude, smoothed);
//   - an integer source gives values rounded to integers, so the
//     quantisation step is 1 value unit per mm (gradient magnitude) or
//     1 value unit (smoothed), stored as uint8 if they fit 0..255, else
//     int16, else uint16, else float32;
//   - an opacity is uint8, opacity * 255 rounded.
// Host-only set-up code; multithreaded over z slabs. Errors in the
// parameters throw InputError naming `name`.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "host_volume.h"

namespace mmrtm {

// |grad v| in value units per mm: central differences along the index axes
// (one-sided at the border, 0 along an axis one voxel thick), turned into a
// world-space gradient through the inverse transpose of indexToWorld, so
// oblique and sheared grids give the true world gradient.
HostVolume GradientMagnitudeProxy(const HostVolume& source, const std::string& name);

// Separable Gaussian of standard deviation sigmaMm (mm) along each index
// axis, i.e. sigmaMm / spacing voxels for that axis's spacing (the length
// of its indexToWorld column). Kernel radius ceil(3 sigma) voxels,
// normalised; voxels beyond the border repeat the border voxel. Throws for
// a sigma that is not positive and finite.
HostVolume SmoothedProxy(const HostVolume& source, float sigmaMm, const std::string& name);

// The opacity of each source voxel under a piecewise-linear TF given as
// [value, opacity] points (ascending values; a repeated value makes a step;
// clamped outside the points; the same curve as a CCTF). Stored as uint8
// opacity * 255 rounded, so TFs reading it use 0..255. Throws for no
// points, descending or non-finite values, or an opacity outside 0..1.
HostVolume OpacityProxy(const HostVolume& source, const std::vector<std::array<float, 2>>& points,
                        const std::string& name);

}  // namespace mmrtm
