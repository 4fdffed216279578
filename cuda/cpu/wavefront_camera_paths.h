// The camera stage of the CPU's SIMD backend (--simd on; issue 34): a
// batch of pixel samples' camera rays delta-tracked together in SIMD lanes
// (cuda/simd/grid_walk_lanes.h: the majorant walk and a plain scene's
// lookups in lanes, a lane a ray), each ray's real-or-null choices made with
// its own random numbers in DeltaTrack's order, and the real collision
// classified by the scalar classifier. A path's free path is the one
// DeltaTrack samples, to the last bit; the rest of the path is the scalar
// integrator (Li, given the free path: wavefront_tile.h).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "mmrtm/integrator.h"

namespace mmrtm {

// A pixel sample on its camera ray, tracked to its free path.
struct CameraPath {
  CameraPath(const SceneView& s, int x, int y, uint32_t sampleIndex)
      : sample(s, x, y, sampleIndex), walk(s, sample.ray, sample.tMax, 1.f) {}

  CameraSample sample;
  TentativeCollisionStart walk;
  DeltaTrackingChoice choice;
  FreePathResult freePath;  // the result
  TraceCounters ctr;        // the work of the camera ray's tracking
};

// Whether this build has the SIMD lanes (MMRTM_ENABLE_SIMD), and the
// instruction set they run on here ("AVX3", "AVX2", ...; "" without them).
bool SimdLookupsBuilt();
const char* SimdLookupTarget();

struct GridWalkLanes;  // cuda/simd/grid_walk_lanes.h

class WavefrontCameraPaths {
 public:
  WavefrontCameraPaths();
  ~WavefrontCameraPaths();

  // Whether the lanes can track `s`'s camera rays: a build with them, delta
  // tracking over a majorant grid (not the one global majorant), indices
  // and a plain scene's voxel offsets within 32 bits.
  static bool Runs(const SceneView& s);

  // Sets every path's freePath (and ctr), as DeltaTrack would with its
  // random numbers; the paths' rngs are left where DeltaTrack leaves them.
  void Track(const SceneView& s, std::vector<CameraPath>& paths, LaneCounters* lanes);

 private:
  std::unique_ptr<GridWalkLanes> walks_;  // the paths' majorant walks, in lanes
  std::vector<uint32_t> walking_;         // the paths in the domain
};

}  // namespace mmrtm
