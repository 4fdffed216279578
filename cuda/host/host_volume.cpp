#include "host_volume.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <thread>
#include <vector>

#include "parallel_for.h"

namespace mmrtm {

bool OnSameVoxelGrid(const HostVolume& v, const HostVolume& grid) {
  if (v.dims != grid.dims) return false;
  // Entry by entry, relative to the largest (origins of a few hundred mm
  // carry rounding of about 1e-5 mm; a composed world-to-index-to-world map
  // would carry it into index units, and miss grids that are the same).
  float scale = 1.f;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      scale = std::max({scale, std::fabs(v.indexToWorld.m[r][c]), std::fabs(grid.indexToWorld.m[r][c])});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      if (std::fabs(v.indexToWorld.m[r][c] - grid.indexToWorld.m[r][c]) > 1e-6f * scale) return false;
  return true;
}

VolumeView HostVolume::View() const {
  VolumeView v;
  v.data = voxels.data();
  v.type = type;
  v.interpolation = interpolation;
  v.SetExtent(dims[0], dims[1], dims[2]);
  try {
    v.worldToIndex = AffineInverse(indexToWorld);
  } catch (const std::runtime_error& e) {
    throw InputError(source + ": " + e.what());
  }
  return v;
}

float HostVolume::Value(int64_t i) const {
  switch (type) {
    case VoxelType::UInt8:
      return (float)voxels[i];
    case VoxelType::Int16:
      return (float)reinterpret_cast<const int16_t*>(voxels.data())[i];
    case VoxelType::UInt16:
      return (float)reinterpret_cast<const uint16_t*>(voxels.data())[i];
    default:
      return reinterpret_cast<const float*>(voxels.data())[i];
  }
}

namespace {
// Minimum and maximum in the voxels' own type: a loop the compiler
// vectorises (Value(i)'s switch per voxel does not), run once per load on
// every thread (a gigabyte volume takes a second on one).
template <typename T>
std::array<float, 2> TypedRange(const T* v, int64_t n) {
  if (n == 0) return {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
  constexpr int64_t kPerThread = int64_t(1) << 24;  // smaller volumes: not worth a thread
  const int threads = (int)std::min<int64_t>(std::max(1u, std::thread::hardware_concurrency()), 1 + n / kPerThread);
  std::vector<std::array<T, 2>> ranges((size_t)threads, {v[0], v[0]});
  RunWorkers(threads, [&](int t) {
    const int64_t begin = n * t / threads, end = n * (t + 1) / threads;
    T lo = v[begin], hi = v[begin];
    for (int64_t i = begin + 1; i < end; ++i) {
      lo = v[i] < lo ? v[i] : lo;
      hi = v[i] > hi ? v[i] : hi;
    }
    ranges[(size_t)t] = {lo, hi};
  });
  T lo = v[0], hi = v[0];
  for (const auto& r : ranges) {
    lo = r[0] < lo ? r[0] : lo;
    hi = r[1] > hi ? r[1] : hi;
  }
  return {(float)lo, (float)hi};
}
}  // namespace

std::array<float, 2> HostVolume::ValueRange() const {
  const int64_t n = VoxelCount();
  switch (type) {
    case VoxelType::UInt8:
      return TypedRange(voxels.data(), n);
    case VoxelType::Int16:
      return TypedRange(reinterpret_cast<const int16_t*>(voxels.data()), n);
    case VoxelType::UInt16:
      return TypedRange(reinterpret_cast<const uint16_t*>(voxels.data()), n);
    default:
      return TypedRange(reinterpret_cast<const float*>(voxels.data()), n);
  }
}

std::array<Vec3, 2> HostVolume::WorldBounds() const {
  Vec3 lo{kInfinity, kInfinity, kInfinity}, hi{-kInfinity, -kInfinity, -kInfinity};
  for (int corner = 0; corner < 8; ++corner) {
    Vec3 idx{(corner & 1) ? float(dims[0] - 1) : 0.f, (corner & 2) ? float(dims[1] - 1) : 0.f,
             (corner & 4) ? float(dims[2] - 1) : 0.f};
    Vec3 w = indexToWorld.ApplyPoint(idx);
    for (int a = 0; a < 3; ++a) {
      lo[a] = Min(lo[a], w[a]);
      hi[a] = Max(hi[a], w[a]);
    }
  }
  return {lo, hi};
}

Vec3 HostVolume::WorldCenter() const {
  return indexToWorld.ApplyPoint({0.5f * (dims[0] - 1), 0.5f * (dims[1] - 1), 0.5f * (dims[2] - 1)});
}

void HostVolume::ReplaceNanVoxels() {
  if (type != VoxelType::Float32) return;
  const int64_t n = std::min<int64_t>(VoxelCount(), (int64_t)(voxels.size() / sizeof(float)));
  const float* in = reinterpret_cast<const float*>(voxels.data());
  float least = std::numeric_limits<float>::infinity();
  int64_t nans = 0;
  for (int64_t i = 0; i < n; ++i)
    if (std::isnan(in[i]))
      ++nans;
    else if (std::isfinite(in[i]))
      least = std::min(least, in[i]);
  if (nans == 0) return;
  if (!std::isfinite(least)) least = 0.f;
  float* f = reinterpret_cast<float*>(voxels.MutableData());
  for (int64_t i = 0; i < n; ++i)
    if (std::isnan(f[i])) f[i] = least;
  nanVoxelsReplaced += nans;
}

void HostVolume::Validate() const {
  const std::string where = source.empty() ? name : source;
  for (int a = 0; a < 3; ++a)
    if (dims[a] <= 0) {
      std::ostringstream msg;
      msg << where << ": empty volume (dimensions " << dims[0] << " x " << dims[1] << " x " << dims[2] << ")";
      throw InputError(msg.str());
    }
  if ((int64_t)voxels.size() != VoxelCount() * VoxelTypeSize(type))
    throw InputError(where + ": voxel buffer size does not match the dimensions");
  if (type == VoxelType::Float32) {
    const float* f = reinterpret_cast<const float*>(voxels.data());
    for (int64_t i = 0, n = VoxelCount(); i < n; ++i)
      if (!std::isfinite(f[i])) {
        std::ostringstream msg;
        msg << where << ": non-finite voxel value (" << f[i] << ") at voxel " << i % dims[0] << ", "
            << (i / dims[0]) % dims[1] << ", " << i / ((int64_t)dims[0] * dims[1]);
        throw InputError(msg.str());
      }
  }
  for (const auto& row : indexToWorld.m)
    for (float v : row)
      if (!std::isfinite(v))
        throw InputError(where + ": its origin, spacing or direction is not finite (or out of float range)");
  const VolumeView view = View();  // throws on singular geometry
  for (const auto& row : view.worldToIndex.m)
    for (float v : row)
      if (!std::isfinite(v)) throw InputError(where + ": its spacing or direction is too close to singular to invert");
}

Affine3 IndexToWorld(const std::array<double, 3>& origin, const std::array<double, 3>& spacing,
                     const std::array<double, 9>& d) {
  Affine3 a;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) a.m[r][c] = (float)(d[3 * r + c] * spacing[c]);
    a.m[r][3] = (float)origin[r];
  }
  return a;
}

}  // namespace mmrtm
