// Delta tracking of many rays in SIMD lanes, a lane a ray: the walk over
// the majorant grid to each tentative collision (GridMajorantIterator::Next:
// the octree's climb / descend / 3D-DDA step, or the macrocell grid's step;
// SampleTentativeCollisions: the optical depth used up segment by
// segment), the extinction there (a plain scene's, in lanes), and the
// caller's real-or-null choice, with masks for the lanes that arrive,
// collide or end early. Every operation is the scalar walk's, in its
// order, so a walk gives the same segments and arrivals to the last bit
// (Testing/Cxx/TestSimdBackend: any drift between the two fails there on
// every scene). A lane's action is an arrival, or Next's climbs and
// descents up to its step out of a node and the first arrival after it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mmrtm/classifier.h"
#include "mmrtm/counters.h"
#include "mmrtm/majorant_grid_view.h"

namespace mmrtm {

// The walks in structure-of-arrays form, slot i walk i: where each starts
// (the lanes take it from here and keep the rest of the walk in
// registers) and, once it ended, how many majorant segments it was handed.
// The last slot is scratch, where padded lanes read and write.
struct GridWalkLanes {
  std::vector<float> o[3], d[3], invD[3], tFace[3];
  std::vector<float> itT, tEnd;  // the grid walk's distance and end
  std::vector<float> tau;        // the optical depth to the first arrival
  std::vector<int32_t> cell[3], level, node;
  std::vector<int32_t> segments;  // the result

  // Room for at least n walks (and whole vectors past them), and the
  // scratch slot after them (an ended walk): the slots a caller does not
  // set keep what they held.
  void Resize(size_t n);
  // Walk i from a scalar walk's state (`tau`: its optical depth to the first
  // arrival).
  void Set(size_t i, const GridWalkState& s, float tau);
};

// Walks [0, count) of `walks` (Resize(count) or more) start as
// GridMajorantIterator's constructor starts them for the index rays
// (o, d) over [t0, t1), scale 1, in lanes; tau is left to the caller.
void StartWalks(const MajorantGridView& grid, const float* const o[3], const float* const d[3], const float* t0,
                const float* t1, size_t count, GridWalkLanes& walks);

// Whether the lanes can walk `grid`: its node indices fit 32 bits.
bool GridWalkLanesFit(const MajorantGridView& grid);

// The caller's side of delta tracking: the choice at each arrival, made
// with the walk's own random numbers, one arrival at a time.
class ArrivalChoices {
 public:
  virtual ~ArrivalChoices() = default;
  // Walk `walk` arrived at distance t, index point p, in a segment of
  // majorant sigma_maj; `plain`: the classification there from the lanes'
  // lookup, or null (a scene not plain: the caller classifies). True for a
  // real collision (the walk is over); otherwise sets *tau, the optical
  // depth to the walk's next arrival.
  virtual bool Real(uint32_t walk, float t, Vec3 p, float sigma_maj, const Classification* plain, float* tau) = 0;
};

// Whether a plain scene's lookups fit the lanes' 32-bit gathers (always
// true for a scene that is not plain: the caller looks up).
bool PlainLookupsFit(const Classifier& classifier);

// Delta-tracks walks ids[0..count) to their first real collision (which
// `choices` records) or their end, as DeltaTrack's walk; adds to `counters`
// (null: none).
void DeltaTrackWalks(const Classifier& classifier, const MajorantGridView& grid, GridTraversal traversal,
                     GridWalkLanes& walks, const uint32_t* ids, size_t count, ArrivalChoices& choices,
                     LaneCounters* counters);

}  // namespace mmrtm
