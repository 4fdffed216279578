// Majorants as an iterator (pbrt-v4's RayMajorantIterator shape): the tracker
// asks for segments {tMin, tMax, sigma_maj} along a ray, one after another,
// and never knows who produced them:
//   Global    one segment over the whole volume (the baseline "none");
//   Macrocell a 3D-DDA over one uniform grid of majorants;
//   Octree    the paper's multi-level traversal of the majorant grid.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/majorant_grid_view.h"
#include "mmrtm/ray.h"

namespace mmrtm {

struct RayMajorantSegment {
  float tMin = 0.f, tMax = 0.f, sigma_maj = 0.f;
  float sigma_min = 0.f;  // a lower bound of sigma_t over the segment (0: none known)
};

enum class MajorantKind : uint8_t { Global, Macrocell, Octree };

// A tagged union of the two iterator shapes (no virtual calls on the GPU).
class MajorantIterator {
 public:
  MajorantIterator() = default;

  MMRTM_CPU_GPU static MajorantIterator Single(float tMin, float tMax, float sigma_maj) {
    MajorantIterator it;
    it.single_ = {tMin, tMax, sigma_maj};
    it.pending_ = tMin < tMax;
    return it;
  }
  // The grid walk is built in place (a copy of its state cost every ray
  // about 55 instructions on the CPU).
  MMRTM_CPU_GPU static MajorantIterator Grid(const MajorantGridView* grid, GridTraversal traversal, const Ray& indexRay,
                                             float tMin, float tMax, float scale) {
    return MajorantIterator(grid, traversal, indexRay, tMin, tMax, scale);
  }

  // The grid walk, or null (one global segment).
  MMRTM_CPU_GPU const GridMajorantIterator* GridWalk() const { return isGrid_ ? &grid_ : nullptr; }

  MMRTM_INLINE MMRTM_CPU_GPU bool Next(RayMajorantSegment* seg) {  // forced: see GridMajorantIterator::Next
    if (isGrid_) return grid_.Next(&seg->tMin, &seg->tMax, &seg->sigma_maj, &seg->sigma_min);
    if (!pending_) return false;
    *seg = single_;
    pending_ = false;
    return true;
  }

 private:
  MMRTM_CPU_GPU MajorantIterator(const MajorantGridView* grid, GridTraversal traversal, const Ray& indexRay, float tMin,
                                 float tMax, float scale)
      : grid_(grid, traversal, indexRay, tMin, tMax, scale), isGrid_(true) {}

  RayMajorantSegment single_;
  GridMajorantIterator grid_;
  bool pending_ = false;
  bool isGrid_ = false;
};

struct MajorantSource {
  MajorantKind kind = MajorantKind::Global;
  float globalMajorant = 0.f;  // bounds sigma_t everywhere in the volume
  MajorantGridView grid;       // Macrocell and Octree

  // Segments over [tMin, tMax] of a ray given in the volume's index space
  // (its parameter t is the world distance). `scale` multiplies every
  // majorant (the shadow-ray extinction scale).
  MMRTM_CPU_GPU MajorantIterator Begin(const Ray& indexRay, float tMin, float tMax, float scale) const {
    if (kind == MajorantKind::Global) return MajorantIterator::Single(tMin, tMax, globalMajorant * scale);
    return MajorantIterator::Grid(&grid,
                                  kind == MajorantKind::Macrocell ? GridTraversal::Macrocell : GridTraversal::Octree,
                                  indexRay, tMin, tMax, scale);
  }
};

}  // namespace mmrtm
