// Synthetic volumes of any voxel type and geometry, for the tests of label
// alignment and derived proxies.
#pragma once

#include <array>
#include <cstring>
#include <functional>

#include "host_volume.h"

namespace mmrtm::test {

template <typename T>
constexpr VoxelType TypeOf() {
  if constexpr (std::is_same_v<T, uint8_t>) return VoxelType::UInt8;
  if constexpr (std::is_same_v<T, int16_t>) return VoxelType::Int16;
  if constexpr (std::is_same_v<T, uint16_t>) return VoxelType::UInt16;
  return VoxelType::Float32;
}

// A volume of voxel type T with value f(i, j, k) and the given geometry.
template <typename T>
HostVolume MakeTyped(std::array<int, 3> dims, const std::function<double(int, int, int)>& f,
                     const Affine3& indexToWorld, const std::string& name = "scalars",
                     Interpolation interpolation = Interpolation::Trilinear) {
  HostVolume v;
  v.name = name;
  v.source = name + ".nrrd";
  v.type = TypeOf<T>();
  v.interpolation = interpolation;
  v.dims = dims;
  v.indexToWorld = indexToWorld;
  v.voxels.resize((size_t)v.VoxelCount() * sizeof(T));
  T* p = reinterpret_cast<T*>(v.voxels.MutableData());
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) p[i + (size_t)dims[0] * (j + (size_t)dims[1] * k)] = (T)f(i, j, k);
  return v;
}

inline Affine3 Grid(std::array<double, 3> origin, std::array<double, 3> spacing,
                    std::array<double, 9> direction = {1, 0, 0, 0, 1, 0, 0, 0, 1}) {
  return IndexToWorld(origin, spacing, direction);
}

// Voxel (i, j, k) of v as a float.
inline float At(const HostVolume& v, int i, int j, int k) {
  return v.Value(i + (int64_t)v.dims[0] * (j + (int64_t)v.dims[1] * k));
}

}  // namespace mmrtm::test
