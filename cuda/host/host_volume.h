// A proxy volume owned on the host: native voxels plus world geometry.
// Host-only set-up code; the tracer sees it through VolumeView.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "mmrtm/volume.h"
#include "voxel_buffer.h"

namespace mmrtm {

// An error in the user's input (a file, a scene, an option). Its message names
// the file or setting and the problem, and is meant to be shown as it is.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct HostVolume {
  std::string name;    // the proxy name scenes refer to, e.g. "scalars"
  std::string source;  // where it came from, for messages
  VoxelType type = VoxelType::UInt8;
  Interpolation interpolation = Interpolation::Trilinear;
  std::array<int, 3> dims{0, 0, 0};
  VoxelBuffer voxels;    // dims[0]*dims[1]*dims[2] values of `type`, x fastest; owned or borrowed
  Affine3 indexToWorld;  // voxel index -> world (millimetres, LPS for medical data)

  // How messages name the volume: its source, else its proxy name.
  const std::string& Where() const { return source.empty() ? name : source; }
  int64_t VoxelCount() const { return (int64_t)dims[0] * dims[1] * dims[2]; }
  VolumeView View() const;                  // throws if the geometry is singular
  float Value(int64_t i) const;             // voxel i converted to float
  std::array<float, 2> ValueRange() const;  // min and max voxel value
  std::array<Vec3, 2> WorldBounds() const;  // axis-aligned world box of the domain
  Vec3 WorldCenter() const;

  // Checks dims, buffer size and (for float voxels) finiteness; throws
  // InputError naming `source` and the problem.
  void Validate() const;

  // Float voxels that are NaN (a hole in a simulation, a failed
  // reconstruction) set to the least finite voxel value (0 when there is
  // none), so that they are as empty as the emptiest voxel under a transfer
  // function that is 0 there (air, background), and interpolation next to
  // them stays finite. Adds their number to nanVoxelsReplaced, for the
  // caller to warn about. Infinite voxels are left (Validate rejects them).
  // Borrowed voxels are copied first, and only when they hold a NaN (the
  // caller's array is never written).
  void ReplaceNanVoxels();
  int64_t nanVoxelsReplaced = 0;
};

// Whether `v` lies on the voxel grid of `grid`: the same dimensions and the
// same index-to-world map to within float rounding (a label map or a derived
// proxy resampled to the image). The tracker then samples `v` at `grid`'s
// index coordinates, and the majorant grid summarizes it over exact voxel
// boxes (Classifier::onProxy0Grid, MajorantGrid).
bool OnSameVoxelGrid(const HostVolume& v, const HostVolume& grid);

// index -> world from origin, spacing and a 3x3 direction matrix (columns are
// the directions of the i, j, k axes), as in ITK and NRRD.
Affine3 IndexToWorld(const std::array<double, 3>& origin, const std::array<double, 3>& spacing,
                     const std::array<double, 9>& directionRowMajor);

}  // namespace mmrtm
