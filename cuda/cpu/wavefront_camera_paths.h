// The camera stage of the CPU's SIMD backend (--simd on, and auto where it
// is faster; issue 34): a batch of pixel samples started in SIMD lanes
// (their numbers, camera rays and walks' starts:
// cuda/simd/camera_path_starts.h), their camera rays delta-tracked
// together in lanes (cuda/simd/grid_walk_lanes.h: the majorant walk and a
// plain scene's lookups, a lane a ray), each ray's real-or-null choices
// made with its own random numbers in DeltaTrack's order, and the real
// collision classified (in a plain scene from the lanes' own lookup,
// otherwise by the scalar classifier). A path's free path is the
// one DeltaTrack samples, to the last bit; the rest of the path is the
// scalar integrator (Li, given the free path: wavefront_tile.h).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "mmrtm/integrator.h"

namespace mmrtm {

// A pixel sample.
struct PixelSampleId {
  int32_t x, y;
  uint32_t index;  // the sample index
};

// A pixel sample on its camera ray, tracked to its free path.
struct CameraPath {
  explicit CameraPath(const CameraSample& s) : sample(s) {}

  CameraSample sample;
  DeltaTrackingChoice choice;
  FreePathResult freePath;  // the result
  TraceCounters ctr;        // the work of the camera ray's tracking
};

// Whether this build has the SIMD lanes (MMRTM_ENABLE_SIMD), the
// instruction set they run on here ("AVX3", "AVX2", ...; "" without them)
// and its floats a vector (16, 8, ...; 0 without them).
bool SimdLookupsBuilt();
const char* SimdLookupTarget();
int SimdLookupLanes();

struct GridWalkLanes;     // cuda/simd/grid_walk_lanes.h
struct CameraPathStarts;  // cuda/simd/camera_path_starts.h

class WavefrontCameraPaths {
 public:
  WavefrontCameraPaths();
  ~WavefrontCameraPaths();

  // Whether the lanes can track `s`'s camera rays: a build with them, delta
  // tracking over a majorant grid (not the one global majorant), indices
  // and a plain scene's voxel offsets within 32 bits.
  static bool Runs(const SceneView& s);
  // Whether they run `s`'s camera stage faster than the scalar tracker
  // does (--simd auto): where they run, start the paths too (the Sobol'
  // sampler, a pinhole), and have kFasterLanes lanes or more (AVX2,
  // AVX-512). Measured on the head CT's camera stage: 16 lanes 1.45-1.51
  // times as fast, 8 lanes 1.13-1.16, 4 lanes (SSE4) 0.81-0.86; with the
  // paths started by the scalar code, 16 lanes 1.06, 8 lanes 0.90
  // (Documentation/performance.md, "SIMD lanes: the camera stage").
  static bool Faster(const SceneView& s);
  static constexpr int kFasterLanes = 8;

  // Makes paths[i] the camera path of samples[i] (as CameraSample) and sets
  // its freePath (and ctr) as DeltaTrack would with its random numbers; the
  // paths' rngs are left where DeltaTrack leaves them. With the Sobol'
  // sampler and a pinhole the samples' numbers, rays and walks start in
  // lanes too (cuda/simd/camera_path_starts.h).
  void Track(const SceneView& s, const std::vector<PixelSampleId>& samples, std::vector<CameraPath>& paths,
             LaneCounters* lanes);

 private:
  std::unique_ptr<GridWalkLanes> walks_;      // the paths' majorant walks, in lanes
  std::unique_ptr<CameraPathStarts> starts_;  // the samples' numbers and rays, in lanes
  std::vector<uint32_t> walking_;             // the paths in the domain
};

}  // namespace mmrtm
