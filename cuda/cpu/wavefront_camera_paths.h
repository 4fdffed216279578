// The first stage of the CPU's SIMD backend (issue 34; decisions.md, "a
// wavefront of stage queues"): the camera rays of many pixel samples are
// delta-tracked to their first real collision together, a round at a
// time. Each round every path still walking advances to its next tentative
// collision (the majorant walk, per path), the extinctions at all those
// points are looked up in SIMD lanes (a plain scene: simd/plain_extinction.h;
// otherwise one Classify a point), and each path makes its real-or-null
// choice. The walk, the choice and the classification of the real
// collision are the scalar tracker's own (mmrtm/tracking.h), each path
// draws its own random numbers in DeltaTrack's order, and the lanes give
// the scalar lookup's bits, so a path's free path is the one DeltaTrack
// samples, to the last bit; the rest of the path is the scalar integrator
// (Li, given the free path).
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
  std::vector<int32_t> collided_;         // each walking path: collided (1) or not (0)
  std::vector<float> t_, x_, y_, z_;      // and where
};

}  // namespace mmrtm
