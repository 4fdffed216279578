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

// One axis of a trilinear lookup at index coordinate p: p clamped to the
// domain [0, last] as Min(Max()), which compiles to two instructions (and
// takes NaN to 0); then the cell's first corner, at least 0 and at most
// lastCell; and p's fraction within that cell.
MMRTM_INLINE MMRTM_CPU_GPU void TrilinearAxis(float p, float last, int lastCell, int* corner, float* t) {
  const float f = Min(Max(p, 0.f), last);
  *corner = MinInt((int)f, lastCell);
  *t = f - (float)*corner;
}

// The voxel nearest to index coordinate p on an axis of voxels 0..last:
// clamped before the truncating conversion (which is the floor on [0,
// last]), and 0 for NaN.
MMRTM_INLINE MMRTM_CPU_GPU int NearestAxis(float p, float last) { return (int)Min(Max(p + 0.5f, 0.f), last); }

// Trilinear interpolation in a cell from its corner values cXYZ (X, Y, Z: 0
// at the first corner, 1 at the far one) at fractions t within it.
MMRTM_INLINE MMRTM_CPU_GPU float InterpolateCell(float c000, float c100, float c010, float c110, float c001,
                                                 float c101, float c011, float c111, float tx, float ty, float tz) {
  const float c00 = Lerp(tx, c000, c100), c10 = Lerp(tx, c010, c110);
  const float c01 = Lerp(tx, c001, c101), c11 = Lerp(tx, c011, c111);
  return Lerp(tz, Lerp(ty, c00, c10), Lerp(ty, c01, c11));
}

// A view of one proxy volume: pointer plus extents, no ownership.
struct VolumeView {
  const void* data = nullptr;
  VoxelType type = VoxelType::UInt8;
  Interpolation interpolation = Interpolation::Trilinear;
  int nx = 0, ny = 0, nz = 0;  // set with SetExtent, which derives the rest
  Affine3 worldToIndex;        // world point -> continuous voxel index
  // Derived from the extent, so that a lookup does not recompute them: the
  // domain's far corner n - 1 per axis; the largest first corner of a
  // trilinear cell (n - 2, or 0 on a flat axis of one voxel); the index
  // steps from a cell's first corner to its far corners along x, y and z
  // (0 on a flat axis, where both corners are the one voxel); nx * ny.
  float last[3] = {};
  int lastCell[3] = {};
  int64_t cornerStep[3] = {};
  int64_t sliceStride = 0;

  MMRTM_CPU_GPU void SetExtent(int x, int y, int z) {
    nx = x;
    ny = y;
    nz = z;
    sliceStride = (int64_t)x * y;
    const int n[3] = {x, y, z};
    const int64_t step[3] = {1, x, sliceStride};
    for (int a = 0; a < 3; ++a) {
      last[a] = (float)(n[a] - 1);
      lastCell[a] = n[a] > 1 ? n[a] - 2 : 0;
      cornerStep[a] = n[a] > 1 ? step[a] : 0;
    }
  }

  MMRTM_CPU_GPU int64_t Offset(int x, int y, int z) const {
    MMRTM_DCHECK(x >= 0 && x < nx && y >= 0 && y < ny && z >= 0 && z < nz);
    return x + (int64_t)nx * y + sliceStride * z;
  }

  MMRTM_CPU_GPU float Voxel(int x, int y, int z) const {
    int64_t o = Offset(x, y, z);
    switch (type) {
      case VoxelType::UInt8:
        return (float)static_cast<const uint8_t*>(data)[o];
      case VoxelType::Int16:
        return (float)static_cast<const int16_t*>(data)[o];
      case VoxelType::UInt16:
        return (float)static_cast<const uint16_t*>(data)[o];
      default:
        return static_cast<const float*>(data)[o];
    }
  }

  // Value at a continuous index position, clamped to the domain.
  MMRTM_INLINE MMRTM_CPU_GPU float SampleIndex(Vec3 p) const {
    if (interpolation == Interpolation::Nearest)
      return Voxel(NearestAxis(p.x, last[0]), NearestAxis(p.y, last[1]),
                   NearestAxis(p.z, last[2]));
    switch (type) {
      case VoxelType::UInt8:
        return Trilinear(static_cast<const uint8_t*>(data), p);
      case VoxelType::Int16:
        return Trilinear(static_cast<const int16_t*>(data), p);
      case VoxelType::UInt16:
        return Trilinear(static_cast<const uint16_t*>(data), p);
      default:
        return Trilinear(static_cast<const float*>(data), p);
    }
  }

  MMRTM_CPU_GPU float SampleWorld(Vec3 world) const { return SampleIndex(worldToIndex.ApplyPoint(world)); }

  // World-space gradient by central differences of the interpolated field,
  // one voxel apart. Used for the surface-scattering normal (paper section 3).
  MMRTM_CPU_GPU Vec3 GradientWorld(Vec3 world) const {
    return worldToIndex.ApplyTransposeLinear(CentralDifferences(worldToIndex.ApplyPoint(world)) * 0.5f);
  }

  // The central differences (twice the index-space gradient) at index
  // position p: six lookups, one voxel either side along each axis. Where
  // all six fall inside the domain without clamping, and p + 1 is exact on
  // every axis, the six cells are the neighbours of p's own cell with p's
  // own fractions (p - 1 and p - floor(p) are exact in float there), so
  // they are read around one cell instead of six separate lookups: the same
  // values to the bit (TestVolumeView checks this against
  // CentralDifferencesBySixLookups), in under half the instructions.
  MMRTM_CPU_GPU Vec3 CentralDifferences(Vec3 p) const {
    if (interpolation == Interpolation::Trilinear && NeighbourCellsAreExact(p)) {
      switch (type) {
        case VoxelType::UInt8:
          return NeighbourDifferences(static_cast<const uint8_t*>(data), p);
        case VoxelType::Int16:
          return NeighbourDifferences(static_cast<const int16_t*>(data), p);
        case VoxelType::UInt16:
          return NeighbourDifferences(static_cast<const uint16_t*>(data), p);
        default:
          return NeighbourDifferences(static_cast<const float*>(data), p);
      }
    }
    return CentralDifferencesBySixLookups(p);
  }

  MMRTM_CPU_GPU Vec3 CentralDifferencesBySixLookups(Vec3 p) const {
    return {SampleIndex({p.x + 1.f, p.y, p.z}) - SampleIndex({p.x - 1.f, p.y, p.z}),
            SampleIndex({p.x, p.y + 1.f, p.z}) - SampleIndex({p.x, p.y - 1.f, p.z}),
            SampleIndex({p.x, p.y, p.z + 1.f}) - SampleIndex({p.x, p.y, p.z - 1.f})};
  }

  // Whether the six lookups of CentralDifferences at p are p's neighbouring
  // cells at p's fractions: on every axis 1 <= p and p + 1 < n - 1 (no
  // clamp, no cell limit; false for NaN), and p + 1 exact (it rounds only
  // where it crosses a power of two with p's last bit set).
  MMRTM_CPU_GPU bool NeighbourCellsAreExact(Vec3 p) const {
    for (int a = 0; a < 3; ++a) {
      const float plus = p[a] + 1.f;
      if (!(p[a] >= 1.f && plus < last[a] && plus - 1.f == p[a])) return false;
    }
    return true;
  }

 private:
  template <typename T>
  MMRTM_CPU_GPU float Trilinear(const T* v, Vec3 p) const {
    int x0, y0, z0;
    float tx, ty, tz;
    TrilinearAxis(p.x, last[0], lastCell[0], &x0, &tx);
    TrilinearAxis(p.y, last[1], lastCell[1], &y0, &ty);
    TrilinearAxis(p.z, last[2], lastCell[2], &z0, &tz);
    return InCell(v + Offset(x0, y0, z0), tx, ty, tz);
  }

  // Trilinear interpolation in the cell whose first corner is c, at
  // fractions t within it.
  template <typename T>
  MMRTM_CPU_GPU float InCell(const T* c, float tx, float ty, float tz) const {
    const int64_t dx = cornerStep[0], dy = cornerStep[1], dz = cornerStep[2];
    return InterpolateCell((float)c[0], (float)c[dx], (float)c[dy], (float)c[dy + dx], (float)c[dz],
                                        (float)c[dz + dx], (float)c[dz + dy], (float)c[dz + dy + dx], tx, ty, tz);
  }

  template <typename T>
  MMRTM_CPU_GPU Vec3 NeighbourDifferences(const T* v, Vec3 p) const {
    const int x0 = (int)p.x, y0 = (int)p.y, z0 = (int)p.z;
    const float tx = p.x - x0, ty = p.y - y0, tz = p.z - z0;
    const T* c = v + Offset(x0, y0, z0);
    const int64_t sy = nx, sz = sliceStride;
    return {InCell(c + 1, tx, ty, tz) - InCell(c - 1, tx, ty, tz),
            InCell(c + sy, tx, ty, tz) - InCell(c - sy, tx, ty, tz),
            InCell(c + sz, tx, ty, tz) - InCell(c - sz, tx, ty, tz)};
  }
};

}  // namespace mmrtm
