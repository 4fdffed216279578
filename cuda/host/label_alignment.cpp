#include "label_alignment.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include "parallel_for.h"

namespace mmrtm {

namespace {

// World box of a volume's domain: its voxels, half a voxel beyond the
// first and last centres (where nearest lookup still finds a voxel).
std::array<Vec3, 2> DomainBox(const HostVolume& v) {
  Vec3 lo{kInfinity, kInfinity, kInfinity}, hi{-kInfinity, -kInfinity, -kInfinity};
  for (int corner = 0; corner < 8; ++corner) {
    Vec3 idx{(corner & 1) ? v.dims[0] - 0.5f : -0.5f, (corner & 2) ? v.dims[1] - 0.5f : -0.5f,
             (corner & 4) ? v.dims[2] - 0.5f : -0.5f};
    Vec3 w = v.indexToWorld.ApplyPoint(idx);
    for (int a = 0; a < 3; ++a) {
      lo[a] = Min(lo[a], w[a]);
      hi[a] = Max(hi[a], w[a]);
    }
  }
  return {lo, hi};
}

std::string BoxText(const std::array<Vec3, 2>& b) {
  std::ostringstream s;
  s.precision(5);
  s << "[" << b[0].x << ", " << b[0].y << ", " << b[0].z << "] - [" << b[1].x << ", " << b[1].y << ", " << b[1].z
    << "] mm";
  return s.str();
}

}  // namespace

HostVolume AlignLabelsToVolume(HostVolume labels, const HostVolume& reference, bool* resampled) {
  if (resampled) *resampled = false;
  // reference index -> label index. View() throws InputError on a singular grid.
  const Affine3 refToLabel = AffineCompose(labels.View().worldToIndex, reference.indexToWorld);
  reference.View();

  // The map is affine, so its largest deviation from the identity over the
  // reference grid is at one of the grid's corners.
  bool same = labels.dims == reference.dims;
  for (int corner = 0; same && corner < 8; ++corner) {
    Vec3 idx{(corner & 1) ? float(reference.dims[0] - 1) : 0.f, (corner & 2) ? float(reference.dims[1] - 1) : 0.f,
             (corner & 4) ? float(reference.dims[2] - 1) : 0.f};
    Vec3 d = refToLabel.ApplyPoint(idx) - idx;
    same = std::fabs(d.x) <= 1e-3f && std::fabs(d.y) <= 1e-3f && std::fabs(d.z) <= 1e-3f;
  }
  if (same) return labels;

  labels.Validate();  // the resampling below reads the voxel buffer
  const auto lb = DomainBox(labels), rb = DomainBox(reference);
  for (int a = 0; a < 3; ++a)
    if (lb[1][a] <= rb[0][a] || rb[1][a] <= lb[0][a])
      throw InputError(labels.Where() + ": the label map (" + BoxText(lb) + ") does not overlap the volume " +
                       reference.Where() + " (" + BoxText(rb) + ")");

  HostVolume out;
  out.name = labels.name;
  out.source = labels.source;
  out.type = labels.type;
  out.interpolation = labels.interpolation;
  out.dims = reference.dims;
  out.indexToWorld = reference.indexToWorld;
  const int bytes = VoxelTypeSize(labels.type);
  out.voxels.assign((size_t)out.VoxelCount() * bytes, 0);  // 0 bytes are label 0 for every type
  uint8_t* aligned = out.voxels.MutableData();

  // Evaluated in double: a float evaluation could put centres that fall
  // exactly on a label voxel boundary on either side, row by row.
  double m[3][4];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m[r][c] = refToLabel.m[r][c];
  const int nx = reference.dims[0], ny = reference.dims[1];
  const int64_t lnx = labels.dims[0], lny = labels.dims[1];
  ParallelFor(reference.dims[2], 0, [&](int64_t z0, int64_t z1) {
    for (int64_t k = z0; k < z1; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          int64_t idx[3];
          bool inside = true;
          for (int a = 0; a < 3 && inside; ++a) {
            idx[a] = (int64_t)std::floor(m[a][0] * i + m[a][1] * j + m[a][2] * k + m[a][3] + 0.5);
            inside = idx[a] >= 0 && idx[a] < labels.dims[a];
          }
          if (!inside) continue;
          const int64_t src = idx[0] + lnx * (idx[1] + lny * idx[2]);
          const int64_t dst = i + (int64_t)nx * (j + (int64_t)ny * k);
          std::memcpy(&aligned[dst * bytes], &labels.voxels[src * bytes], bytes);
        }
  });

  bool any = false;
  for (int64_t i = 0, n = out.VoxelCount(); i < n && !any; ++i) any = out.Value(i) != 0.f;
  if (!any)
    throw InputError(labels.Where() + ": no label is left after resampling the label map onto the grid of " +
                     reference.Where() + " (label box " + BoxText(lb) + ", volume box " + BoxText(rb) + ")");
  if (resampled) *resampled = true;
  return out;
}

}  // namespace mmrtm
