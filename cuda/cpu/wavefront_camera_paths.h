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
#include <vector>

#include "mmrtm/integrator.h"

namespace mmrtm {

// How full a stage kept its SIMD lanes: `items` points over `lanes` lanes
// run (a call over n points runs n rounded up to the vector's width).
struct LaneCounters {
  uint64_t calls = 0, items = 0, lanes = 0;
  LaneCounters& operator+=(const LaneCounters& o) {
    calls += o.calls;
    items += o.items;
    lanes += o.lanes;
    return *this;
  }
};

// A pixel sample on its camera ray, tracked to its free path.
struct CameraPath {
  CameraPath(const SceneView& s, int x, int y, uint32_t sampleIndex)
      : sample(s, x, y, sampleIndex), walk(s, sample.ray, sample.tMax, 1.f) {}

  CameraSample sample;
  TentativeCollisionWalk<false> walk;
  DeltaTrackingChoice choice;
  FreePathResult freePath;  // the result
  TraceCounters ctr;        // the work of the camera ray's tracking
};

// Whether this build has the SIMD lookups (MMRTM_ENABLE_SIMD), and the
// instruction set they run on here ("AVX3", "AVX2", ...; "" without them).
bool SimdLookupsBuilt();
const char* SimdLookupTarget();

class WavefrontCameraPaths {
 public:
  // Sets every path's freePath (and ctr), as DeltaTrack would with its
  // random numbers; the paths' rngs are left where DeltaTrack leaves them.
  // `simd` false: the lookups one point at a time (the same bits).
  void Track(const SceneView& s, std::vector<CameraPath>& paths, bool simd, LaneCounters* lanes);

 private:
  // sigma_t_ (and classified_ where the lanes do not run) of the arrivals.
  void Lookup(const SceneView& s, const std::vector<CameraPath>& paths, bool simd, LaneCounters* lanes);

  std::vector<uint32_t> walking_, arrived_;  // path indices
  std::vector<float> x_, y_, z_, sigma_t_;   // the arrivals' index points and extinctions
  std::vector<Classification> classified_;   // a scene not plain: the arrivals' classifications
};

}  // namespace mmrtm
