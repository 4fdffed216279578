// Proxy volumes in their native voxel type, with world geometry.
//
// Voxel centres sit at integer index coordinates; the volume's domain is the
// box between the first and the last voxel centre, [0, n-1] on each axis (as
// vtkImageData bounds). Continuous proxies are sampled trilinearly, discrete
// ones (label maps) with nearest lookup (paper section 5), so that a label
// never takes an undefined in-between value.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

enum class VoxelType : uint8_t { UInt8, Int16, UInt16, Float32 };
enum class Interpolation : uint8_t { Trilinear, Nearest };

MMRTM_CPU_GPU inline int VoxelTypeSize(VoxelType t) {
  return t == VoxelType::UInt8 ? 1 : (t == VoxelType::Float32 ? 4 : 2);
}

// A view of one proxy volume: pointer plus extents, no ownership.
struct VolumeView {
  const void* data = nullptr;
  VoxelType type = VoxelType::UInt8;
  Interpolation interpolation = Interpolation::Trilinear;
  int nx = 0, ny = 0, nz = 0;
  Affine3 worldToIndex;  // world point -> continuous voxel index

  // The voxel nearest to index coordinate x on an axis of n voxels, clamped
  // to the axis (and 0 for NaN).
  MMRTM_CPU_GPU static int NearestIndex(float x, int n) { return FloorClamped(x + 0.5f, n - 1); }

  MMRTM_CPU_GPU int64_t Offset(int x, int y, int z) const {
    MMRTM_DCHECK(x >= 0 && x < nx && y >= 0 && y < ny && z >= 0 && z < nz);
    return x + (int64_t)nx * (y + (int64_t)ny * z);
  }

  MMRTM_CPU_GPU float Voxel(int x, int y, int z) const {
    int64_t o = Offset(x, y, z);
    switch (type) {
      case VoxelType::UInt8: return (float)static_cast<const uint8_t*>(data)[o];
      case VoxelType::Int16: return (float)static_cast<const int16_t*>(data)[o];
      case VoxelType::UInt16: return (float)static_cast<const uint16_t*>(data)[o];
      default: return static_cast<const float*>(data)[o];
    }
  }

  // Value at a continuous index position, clamped to the domain.
  MMRTM_CPU_GPU float SampleIndex(Vec3 p) const {
    if (interpolation == Interpolation::Nearest)
      return Voxel(NearestIndex(p.x, nx), NearestIndex(p.y, ny), NearestIndex(p.z, nz));
    switch (type) {
      case VoxelType::UInt8: return Trilinear(static_cast<const uint8_t*>(data), p);
      case VoxelType::Int16: return Trilinear(static_cast<const int16_t*>(data), p);
      case VoxelType::UInt16: return Trilinear(static_cast<const uint16_t*>(data), p);
      default: return Trilinear(static_cast<const float*>(data), p);
    }
  }

  MMRTM_CPU_GPU float SampleWorld(Vec3 world) const { return SampleIndex(worldToIndex.ApplyPoint(world)); }

  // World-space gradient by central differences of the interpolated field,
  // one voxel apart. Used for the surface-scattering normal (paper section 3).
  MMRTM_CPU_GPU Vec3 GradientWorld(Vec3 world) const {
    Vec3 p = worldToIndex.ApplyPoint(world);
    Vec3 g{SampleIndex({p.x + 1.f, p.y, p.z}) - SampleIndex({p.x - 1.f, p.y, p.z}),
           SampleIndex({p.x, p.y + 1.f, p.z}) - SampleIndex({p.x, p.y - 1.f, p.z}),
           SampleIndex({p.x, p.y, p.z + 1.f}) - SampleIndex({p.x, p.y, p.z - 1.f})};
    return worldToIndex.ApplyTransposeLinear(g * 0.5f);
  }

 private:
  template <typename T>
  MMRTM_CPU_GPU float Trilinear(const T* v, Vec3 p) const {
    // Clamped to the domain as Min(Max()), which compiles to two
    // instructions (and takes NaN to 0); then the cell's first corner, which
    // is at least 0 and at most n - 2 (0 on a flat axis of one voxel).
    const float fx = Min(Max(p.x, 0.f), (float)(nx - 1)), fy = Min(Max(p.y, 0.f), (float)(ny - 1)),
                fz = Min(Max(p.z, 0.f), (float)(nz - 1));
    const int x0 = MinInt((int)fx, nx > 1 ? nx - 2 : 0), y0 = MinInt((int)fy, ny > 1 ? ny - 2 : 0),
              z0 = MinInt((int)fz, nz > 1 ? nz - 2 : 0);
    int dx = nx > 1 ? 1 : 0, dy = ny > 1 ? nx : 0;
    int64_t dz = nz > 1 ? (int64_t)nx * ny : 0;
    float tx = fx - x0, ty = fy - y0, tz = fz - z0;
    const T* c = v + Offset(x0, y0, z0);
    float c00 = Lerp(tx, (float)c[0], (float)c[dx]);
    float c10 = Lerp(tx, (float)c[dy], (float)c[dy + dx]);
    float c01 = Lerp(tx, (float)c[dz], (float)c[dz + dx]);
    float c11 = Lerp(tx, (float)c[dz + dy], (float)c[dz + dy + dx]);
    return Lerp(tz, Lerp(ty, c00, c10), Lerp(ty, c01, c11));
  }
};

}  // namespace mmrtm
