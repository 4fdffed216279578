// The hierarchical majorant grid (paper section 4) as the tracker sees it:
// an octree stored as one uniform grid per level, level 0 the root and level
// `leafLevel` the leaves, and the iterator that walks it along a ray.
//
// Node (x, y, z) of level l covers the voxel cells [x s_l, (x+1) s_l) (and so
// on for y, z) of the volume's index space, clipped to the volume, with
// s_l = leafSize * 2^(leafLevel - l). Parent and children follow from the
// integer coordinates (x >> 1; 2x and 2x + 1), bounds from s_l, so the flat
// list stores only one majorant per node, level after level.
//
// Traversal (paper section 4), in a node of optical thickness
// tau = sigma_maj * scale * width_l:
//   - an empty node climbs to its highest empty ancestor, which is skipped;
//   - tau below kClimbOpticalThickness climbs, unless the parent's tau is
//     above kDescendOpticalThickness;
//   - tau above kDescendOpticalThickness descends to the child under the ray;
//   - otherwise (or at the root or a leaf) the node is one majorant segment,
//     and the walk continues with its neighbour on the same level (3D-DDA).
// A walk starts at the leaf under the ray's first point and applies the same
// rules from there (it climbs as far as they allow before its first segment).
// The paper states its thresholds 0.2 and 0.6 on the "maximum attenuation
// coefficient" of a node; here they apply to the node's optical thickness
// (majorant times node width), which makes them independent of units and
// voxel size: it is the expected number of tentative collisions per node,
// and what decides whether a finer or coarser node pays off.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/ray.h"

namespace mmrtm {

constexpr int kMaxGridLevels = 12;
constexpr float kClimbOpticalThickness = 0.2f;    // paper section 4
constexpr float kDescendOpticalThickness = 0.6f;  // paper section 4

enum class GridTraversal : uint8_t {
  Macrocell,  // 3D-DDA over the leaf level only (the uniform-grid baseline)
  Octree      // the paper's multi-level traversal
};

struct MajorantGridView {
  int leafLevel = 0;                      // levels 0..leafLevel
  int cells[3] = {1, 1, 1};               // voxel cells per axis (n - 1, at least 1)
  int res[kMaxGridLevels][3] = {};        // nodes per axis, per level
  int nodeSize[kMaxGridLevels] = {};      // node width in voxel cells, per level
  int64_t offset[kMaxGridLevels] = {};    // first node of each level in `majorants`
  float worldWidth[kMaxGridLevels] = {};  // node width in world units (largest axis)
  const float* majorants = nullptr;       // sigma_t bound of every node, level after level
  // A lower bound of sigma_t in every node, indexed as `majorants`, as a
  // fraction of the node's majorant in 255ths (DecodeMinorant): the control
  // of residual ratio tracking (tracking.h). A byte, not a float, so that
  // the grid grows by a quarter and not by half; null: 0 everywhere.
  const uint8_t* minorants = nullptr;

  MMRTM_CPU_GPU int64_t Index(int level, int x, int y, int z) const {
    MMRTM_DCHECK(x >= 0 && x < res[level][0] && y >= 0 && y < res[level][1] && z >= 0 && z < res[level][2]);
    return offset[level] + x + (int64_t)res[level][0] * (y + (int64_t)res[level][1] * z);
  }
  MMRTM_CPU_GPU float Majorant(int level, const int c[3]) const { return majorants[Index(level, c[0], c[1], c[2])]; }
};

// A node's minorant from its majorant and its byte (MajorantGridView::minorants).
// 255 gives the majorant itself, so that a constant node's residual is
// exactly 0 (255 * (1 / 255.f) rounds below 1).
MMRTM_CPU_GPU inline float DecodeMinorant(float majorant, uint8_t fraction) {
  return fraction == 255 ? majorant : majorant * ((float)fraction * (1.f / 255.f));
}
// The largest byte whose decoded minorant stays at most `minorant` (0 when
// either bound is 0 or NaN): rounding down keeps it a lower bound.
MMRTM_CPU_GPU inline uint8_t EncodeMinorant(float majorant, float minorant) {
  if (!(majorant > 0.f) || !(minorant > 0.f)) return 0;
  int q = minorant >= majorant ? 255 : (int)(255.f * (minorant / majorant));
  while (q > 0 && DecodeMinorant(majorant, (uint8_t)q) > minorant) --q;
  return (uint8_t)q;
}

// Walks the grid along a ray given in voxel index space (its parameter t is
// the world distance), handing out majorant segments.
class GridMajorantIterator {
 public:
  GridMajorantIterator() = default;
  MMRTM_CPU_GPU GridMajorantIterator(const MajorantGridView* grid, GridTraversal traversal, const Ray& r, float tMin,
                                     float tMax, float scale)
      : grid_(grid), o_(r.o), d_(r.d), t_(tMin), tEnd_(tMax), scale_(scale), traversal_(traversal) {
    // Both start at the leaf the ray begins in. For the octree that is where
    // most rays begin (scattered and shadow rays start in matter) and the
    // rules below climb from there where nodes are thin or empty; starting
    // at the root cost every ray a descent through all levels.
    level_ = grid->leafLevel;
    // A multiply per face crossing instead of a division (0 where the ray
    // is parallel to an axis, whose faces FaceAhead never crosses), and the
    // time at which the ray leaves the grid's last cell ahead (the last node
    // of an axis is clipped to the volume).
    for (int a = 0; a < 3; ++a) {
      invD_[a] = d_[a] != 0.f ? 1.f / d_[a] : 0.f;
      step_[a] = d_[a] > 0.f ? 1 : (d_[a] < 0.f ? -1 : 0);
      tClip_[a] = d_[a] > 0.f ? ((float)grid->cells[a] - o_[a]) * invD_[a] : kInfinity;
    }
    Vec3 p = r(tMin);
    for (int a = 0; a < 3; ++a) {
      float x = p[a] / (float)grid->nodeSize[level_];
      cell_[a] = FloorClamped(x, grid->res[level_][a] - 1);
    }
    EnterLevel();
  }

  // The next segment with a non-zero majorant, and a lower bound of the
  // extinction over it (0 without minorants); false at the end of the ray.
  // Forced inline: called for every segment, and GCC kept it out of line
  // once it had four results (8 % more instructions on the chest CT).
  MMRTM_INLINE MMRTM_CPU_GPU bool Next(float* tMin, float* tMax, float* sigma_maj, float* sigma_min) {
    while (t_ < tEnd_) {
      const float maj = grid_->majorants[node_];
      if (maj <= 0.f) {
        if (traversal_ == GridTraversal::Octree) ClimbToHighestEmptyAncestor();
        int axis;
        float tExit = ExitDistance(&axis);
        if (!Step(axis, tExit)) return false;
        continue;
      }
      if (traversal_ == GridTraversal::Octree) {
        const float tau = maj * scale_ * grid_->worldWidth[level_];
        if (tau < kClimbOpticalThickness && level_ > 0) {
          const int parent[3] = {cell_[0] >> 1, cell_[1] >> 1, cell_[2] >> 1};
          if (grid_->Majorant(level_ - 1, parent) * scale_ * grid_->worldWidth[level_ - 1] <=
              kDescendOpticalThickness) {
            Climb();
            continue;
          }
        } else if (tau > kDescendOpticalThickness && level_ < grid_->leafLevel) {
          Descend();
          continue;
        }
      }
      int axis;
      const float tExit = ExitDistance(&axis);
      *tMin = t_;
      *sigma_maj = maj * scale_;
      *sigma_min = grid_->minorants ? DecodeMinorant(*sigma_maj, grid_->minorants[node_]) : 0.f;
      // The last node of the ray takes the rest of [tMin, tMax]: the box test
      // widens the far end by a few ulps, where lookups clamp to this node.
      *tMax = Step(axis, tExit) ? tExit : tEnd_;
      return true;
    }
    return false;
  }

 private:
  // After a change of level: the node's width, its index, the index steps
  // to its neighbours and the crossing times of its faces ahead (kept so
  // that a step along an axis is an add and one crossing time).
  MMRTM_CPU_GPU void EnterLevel() {
    size_ = (float)grid_->nodeSize[level_];
    stride_[0] = 1;
    stride_[1] = grid_->res[level_][0];
    stride_[2] = (int64_t)grid_->res[level_][0] * grid_->res[level_][1];
    node_ = grid_->Index(level_, cell_[0], cell_[1], cell_[2]);
    for (int a = 0; a < 3; ++a) FaceAhead(a);
  }

  // The crossing time of the current node's face ahead on axis a, or of the
  // volume's end where it clips the node: the earlier of the two crossing
  // times is the crossing of the nearer plane (x -> (x - o) / d keeps the
  // order). kInfinity where the ray is parallel to the axis.
  MMRTM_CPU_GPU void FaceAhead(int a) {
    if (step_[a] == 0) {
      tFace_[a] = kInfinity;
      return;
    }
    const float plane = (float)(cell_[a] + (step_[a] > 0 ? 1 : 0)) * size_;
    tFace_[a] = Min((plane - o_[a]) * invD_[a], tClip_[a]);
  }

  MMRTM_CPU_GPU void Climb() {
    --level_;
    for (int a = 0; a < 3; ++a) cell_[a] >>= 1;
    EnterLevel();
  }

  MMRTM_CPU_GPU void ClimbToHighestEmptyAncestor() {
    int top = level_;
    while (top > 0) {
      const int shift = level_ - top + 1;
      const int parent[3] = {cell_[0] >> shift, cell_[1] >> shift, cell_[2] >> shift};
      if (grid_->Majorant(top - 1, parent) > 0.f) break;
      --top;
    }
    if (top == level_) return;
    for (int a = 0; a < 3; ++a) cell_[a] >>= level_ - top;
    level_ = top;
    EnterLevel();
  }

  // Into the child that the ray is in at t (ties go to the side it heads to).
  MMRTM_CPU_GPU void Descend() {
    const int child = level_ + 1;
    const float size = (float)grid_->nodeSize[child];
    Vec3 p = o_ + d_ * t_;
    for (int a = 0; a < 3; ++a) {
      float mid = (float)(2 * cell_[a] + 1) * size;
      float rel = p[a] - mid;
      bool upper = fabsf(rel) <= 1e-4f * size ? d_[a] > 0.f : rel > 0.f;
      cell_[a] = ClampInt(2 * cell_[a] + (upper ? 1 : 0), 0, grid_->res[child][a] - 1);
    }
    level_ = child;
    EnterLevel();
  }

  // Where the ray leaves the current node, and through which face (-1 when
  // the ray ends inside it).
  MMRTM_CPU_GPU float ExitDistance(int* axisOut) const {
    float tExit = tEnd_;
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
      const float t = tFace_[a];
      if (t < tExit) {
        tExit = t;
        axis = a;
      }
    }
    *axisOut = axis;
    return Max(tExit, t_);
  }

  // Moves to the neighbour across face `axis` at tExit; false when the ray
  // leaves the grid or ends.
  MMRTM_CPU_GPU bool Step(int axis, float tExit) {
    t_ = tExit;
    if (axis < 0 || t_ >= tEnd_) {
      t_ = tEnd_;
      return false;
    }
    cell_[axis] += step_[axis];
    if (cell_[axis] < 0 || cell_[axis] >= grid_->res[level_][axis]) {
      t_ = tEnd_;
      return false;
    }
    node_ += step_[axis] * stride_[axis];
    FaceAhead(axis);
    return true;
  }

  const MajorantGridView* grid_ = nullptr;
  Vec3 o_, d_;
  float invD_[3] = {0.f, 0.f, 0.f};
  float t_ = 0.f, tEnd_ = 0.f, scale_ = 1.f;
  int level_ = 0;
  int cell_[3] = {0, 0, 0};
  int step_[3] = {0, 0, 0};           // +1, -1 or 0: the ray's direction per axis
  float tClip_[3] = {0.f, 0.f, 0.f};  // where it leaves the grid's last cell ahead (kInfinity: d <= 0)
  float size_ = 1.f;                  // node width of level_, in voxel cells
  int64_t node_ = 0;                  // the index of (level_, cell_)
  int64_t stride_[3] = {1, 1, 1};     // index steps to the neighbours on level_
  float tFace_[3] = {0.f, 0.f, 0.f};  // FaceAhead
  GridTraversal traversal_ = GridTraversal::Octree;
};

}  // namespace mmrtm
