// Compiled once per Highway target (foreach_target.h re-includes this file),
// with -ffp-contract=off (cuda/CMakeLists.txt), so that every operation
// rounds as the scalar walk's does. The scalar walk, mirrored here operation
// by operation, is GridMajorantIterator (mmrtm/majorant_grid_view.h) and
// the loop of SampleTentativeCollisions (mmrtm/tracking.h) for delta tracking.
#include "grid_walk_lanes.h"

#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "simd/grid_walk_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "simd/plain_extinction-inl.h"

HWY_BEFORE_NAMESPACE();
namespace mmrtm {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using MF = hn::Mask<DF>;

// The grid's per-level numbers, looked up by level (ByLevel), padded for
// whole-vector loads.
constexpr int kLevelTableSize = kMaxGridLevels + HWY_MAX_BYTES / 4;
struct LevelTables {
  int32_t nodeSize[kLevelTableSize], res[3][kLevelTableSize], offset[kLevelTableSize];
  float worldWidth[kLevelTableSize];
  float cells[3];  // voxel cells per axis (the grid's end)
};

// table[level] in each lane: in-register permutes of the small table
// (one on AVX-512, where 16 lanes hold every level), not gathers.
template <class D>
HWY_INLINE hn::Vec<D> ByLevel(D d, const hn::TFromD<D>* table, hn::Vec<DI> level) {
  const int n = (int)hn::Lanes(d);
  hn::Vec<D> value = hn::Zero(d);
  for (int first = 0; first < kMaxGridLevels; first += n) {
    const hn::Vec<DI> index = hn::Min(hn::Max(level - hn::Set(DI(), first), hn::Zero(DI())), hn::Set(DI(), n - 1));
    const hn::Vec<D> chunk = hn::TableLookupLanes(hn::LoadU(d, table + first), hn::IndicesFromVec(d, index));
    value = first == 0 ? chunk : hn::IfThenElse(hn::RebindMask(d, hn::Not(level < hn::Set(DI(), first))), chunk, value);
  }
  return value;
}
HWY_INLINE hn::Vec<DI> LevelI(const int32_t* table, hn::Vec<DI> level) { return ByLevel(DI(), table, level); }
HWY_INLINE hn::Vec<DF> LevelF(const float* table, hn::Vec<DI> level) { return ByLevel(DF(), table, level); }

HWY_INLINE MF ToF(hn::Mask<DI> m) { return hn::RebindMask(DF(), m); }
HWY_INLINE VF Sel(MF m, VF yes, VF no) { return hn::IfThenElse(m, yes, no); }
HWY_INLINE VI SelI(MF m, VI yes, VI no) { return hn::IfThenElse(hn::RebindMask(DI(), m), yes, no); }
// mmrtm::Min and Max: a < b ? a : b and a > b ? a : b on every target.
HWY_INLINE VF MinF(VF a, VF b) { return hn::IfThenElse(a < b, a, b); }
HWY_INLINE VF MaxF(VF a, VF b) { return hn::IfThenElse(a > b, a, b); }
HWY_INLINE VI GatherI(const int32_t* base, VI index) { return hn::GatherIndex(DI(), base, index); }
HWY_INLINE VF GatherF(const float* base, VI index) { return hn::GatherIndex(DF(), base, index); }

// The lanes' walks (GridWalkLanes' fields, one lane a walk). What the
// scalar iterator keeps beside them (its step per axis, node size and index
// strides) is derived when needed: fewer vectors live across the loop.
struct Walks {
  VF o[3], d[3], invD[3], tFace[3];
  VF itT, tEnd, walkT, tau, segTMax, segMaj;
  VI cell[3], level, node, segments;
  MF inSegment, emptyClimb;
};

// GridMajorantIterator's step_[a]: +1, -1 or 0, the ray's direction.
HWY_INLINE VI StepOf(const Walks& w, int a) {
  const VI up = hn::Set(DI(), 1), down = hn::Set(DI(), -1), zero = hn::Zero(DI());
  return hn::IfThenElse(hn::RebindMask(DI(), w.d[a] > hn::Zero(DF())), up,
                        hn::IfThenElse(hn::RebindMask(DI(), w.d[a] < hn::Zero(DF())), down, zero));
}
// The node size (voxel cells) and the index stride along axis a of a level.
HWY_INLINE VF SizeOf(const LevelTables& tables, VI level) {
  return hn::ConvertTo(DF(), LevelI(tables.nodeSize, level));
}
HWY_INLINE VI StrideOf(const LevelTables& tables, VI level, int a) {
  if (a == 0) return hn::Set(DI(), 1);
  const VI res0 = LevelI(tables.res[0], level);
  return a == 1 ? res0 : res0 * LevelI(tables.res[1], level);
}

// GridMajorantIterator::FaceAhead(a) for the lanes' current nodes.
HWY_INLINE VF FaceAhead(const LevelTables& tables, const Walks& w, int a) {
  const VI one = hn::Set(DI(), 1), zero = hn::Zero(DI()), step = StepOf(w, a);
  const VI ahead = w.cell[a] + hn::IfThenElse(step > zero, one, zero);
  const VF plane = hn::ConvertTo(DF(), ahead) * SizeOf(tables, w.level);
  // tClip_[a]: where the ray leaves the grid's last cell ahead.
  const VF inf = hn::Set(DF(), std::numeric_limits<float>::infinity());
  const VF tClip = hn::IfThenElse(w.d[a] > hn::Zero(DF()), (hn::Set(DF(), tables.cells[a]) - w.o[a]) * w.invD[a], inf);
  const VF t = MinF((plane - w.o[a]) * w.invD[a], tClip);
  return hn::IfThenElse(ToF(step == zero), inf, t);
}

// GridMajorantIterator::EnterLevel in the lanes of `m` (their level and
// cells set already).
HWY_INLINE void EnterLevel(const LevelTables& tables, MF m, Walks& w) {
  const VI node = LevelI(tables.offset, w.level) + w.cell[0] +
                  LevelI(tables.res[0], w.level) * (w.cell[1] + LevelI(tables.res[1], w.level) * w.cell[2]);
  w.node = SelI(m, node, w.node);
  for (int a = 0; a < 3; ++a) w.tFace[a] = Sel(m, FaceAhead(tables, w, a), w.tFace[a]);
}

// GridMajorantIterator::ExitDistance: where each lane leaves its node, and
// through which axis (-1: the ray ends inside it).
HWY_INLINE VF ExitDistance(const Walks& w, VI* axis) {
  VF tExit = w.tEnd;
  *axis = hn::Set(DI(), -1);
  for (int a = 0; a < 3; ++a) {
    const MF nearer = w.tFace[a] < tExit;
    tExit = Sel(nearer, w.tFace[a], tExit);
    *axis = SelI(nearer, hn::Set(DI(), a), *axis);
  }
  return MaxF(tExit, w.itT);
}

// GridMajorantIterator::Step in the lanes of `m`; the lanes that moved to
// a neighbour (the others' walks end: itT = tEnd).
HWY_INLINE MF Step(const LevelTables& tables, MF m, VI axis, VF tExit, Walks& w) {
  w.itT = Sel(m, tExit, w.itT);
  MF fail = hn::And(m, hn::Or(ToF(axis < hn::Zero(DI())), tExit >= w.tEnd));
  const MF go = hn::AndNot(fail, m);
  MF moved = hn::FirstN(DF(), 0);
  for (int a = 0; a < 3; ++a) {
    const MF along = hn::And(go, ToF(axis == hn::Set(DI(), a)));
    if (hn::AllFalse(DF(), along)) continue;
    const VI step = StepOf(w, a);
    const VI next = w.cell[a] + step;
    const MF out = ToF(hn::Or(next < hn::Zero(DI()), hn::Not(next < LevelI(tables.res[a], w.level))));
    w.cell[a] = SelI(along, next, w.cell[a]);
    fail = hn::Or(fail, hn::And(along, out));
    const MF in = hn::AndNot(out, along);
    w.node = SelI(in, w.node + step * StrideOf(tables, w.level, a), w.node);
    w.tFace[a] = Sel(in, FaceAhead(tables, w, a), w.tFace[a]);
    moved = hn::Or(moved, in);
  }
  w.itT = Sel(fail, w.tEnd, w.itT);
  return moved;
}

// Into the child each lane of `m` is in at itT (GridMajorantIterator::Descend).
HWY_INLINE void Descend(const LevelTables& tables, int leafLevel, MF m, Walks& w) {
  const VI child = hn::Min(w.level + hn::Set(DI(), 1), hn::Set(DI(), leafLevel));
  const VF size = hn::ConvertTo(DF(), LevelI(tables.nodeSize, child));
  const VI one = hn::Set(DI(), 1), zero = hn::Zero(DI());
  for (int a = 0; a < 3; ++a) {
    const VF p = w.o[a] + w.d[a] * w.itT;
    const VI twice = w.cell[a] + w.cell[a];
    const VF mid = hn::ConvertTo(DF(), twice + one) * size;
    const VF rel = p - mid;
    const MF nearMid = hn::Abs(rel) <= hn::Set(DF(), 1e-4f) * size;  // ties go to the side the ray heads to
    const MF upper = hn::Or(hn::And(nearMid, w.d[a] > hn::Zero(DF())), hn::AndNot(nearMid, rel > hn::Zero(DF())));
    const VI cell = twice + hn::IfThenElse(hn::RebindMask(DI(), upper), one, zero);
    const VI clamped = hn::Min(hn::Max(cell, zero), LevelI(tables.res[a], child) - one);
    w.cell[a] = SelI(m, clamped, w.cell[a]);
  }
  w.level = SelI(m, child, w.level);
  EnterLevel(tables, m, w);
}

// One level up in the lanes of `m` (GridMajorantIterator::Climb, and a step
// of ClimbToHighestEmptyAncestor).
HWY_INLINE void Climb(const LevelTables& tables, MF m, Walks& w) {
  w.level = SelI(m, w.level - hn::Set(DI(), 1), w.level);
  for (int a = 0; a < 3; ++a) w.cell[a] = SelI(m, hn::ShiftRight<1>(w.cell[a]), w.cell[a]);
  EnterLevel(tables, m, w);
}

// Loads the walks `id` into lanes.
HWY_INLINE void LoadWalks(const GridWalkLanes& walks, VI id, Walks& w) {
  const VI zero = hn::Zero(DI());
  for (int a = 0; a < 3; ++a) {
    w.o[a] = GatherF(walks.o[a].data(), id);
    w.d[a] = GatherF(walks.d[a].data(), id);
    w.invD[a] = GatherF(walks.invD[a].data(), id);
    w.tFace[a] = GatherF(walks.tFace[a].data(), id);
    w.cell[a] = GatherI(walks.cell[a].data(), id);
  }
  w.itT = GatherF(walks.itT.data(), id);
  w.tEnd = GatherF(walks.tEnd.data(), id);
  w.walkT = GatherF(walks.walkT.data(), id);
  w.tau = GatherF(walks.tau.data(), id);
  w.segTMax = GatherF(walks.segTMax.data(), id);
  w.segMaj = GatherF(walks.segMaj.data(), id);
  w.level = GatherI(walks.level.data(), id);
  w.node = GatherI(walks.node.data(), id);
  w.segments = GatherI(walks.segments.data(), id);
  w.inSegment = ToF(GatherI(walks.inSegment.data(), id) != zero);
  w.emptyClimb = ToF(GatherI(walks.emptyClimb.data(), id) != zero);
}

// Stores what a walk changes of the lanes' walks `id`.
HWY_INLINE void StoreWalks(const Walks& w, VI id, GridWalkLanes& walks) {
  const DF df;
  const DI di;
  const VI one = hn::Set(di, 1), zero = hn::Zero(di);
  for (int a = 0; a < 3; ++a) {
    hn::ScatterIndex(w.tFace[a], df, walks.tFace[a].data(), id);
    hn::ScatterIndex(w.cell[a], di, walks.cell[a].data(), id);
  }
  hn::ScatterIndex(w.itT, df, walks.itT.data(), id);
  hn::ScatterIndex(w.walkT, df, walks.walkT.data(), id);
  hn::ScatterIndex(w.tau, df, walks.tau.data(), id);
  hn::ScatterIndex(w.segTMax, df, walks.segTMax.data(), id);
  hn::ScatterIndex(w.segMaj, df, walks.segMaj.data(), id);
  hn::ScatterIndex(w.level, di, walks.level.data(), id);
  hn::ScatterIndex(w.node, di, walks.node.data(), id);
  hn::ScatterIndex(w.segments, di, walks.segments.data(), id);
  hn::ScatterIndex(SelI(w.inSegment, one, zero), di, walks.inSegment.data(), id);
  hn::ScatterIndex(SelI(w.emptyClimb, one, zero), di, walks.emptyClimb.data(), id);
}

// One action of every lane in `live`: an arrival in its segment or the
// segment used up, then, between segments, the grid walk's next action
// (GridMajorantIterator::Next: a climb, a descent, a step out of an empty
// node, or a segment handed out) or its end. Returns the lanes whose walk
// ended; `arrived`: the lanes at an arrival.
HWY_INLINE MF Act(const MajorantGridView& grid, const LevelTables& tables, bool octree, VF scale, MF live, Walks& w,
                  MF* arrived) {
  const DF df;
  const DI di;
  const VF zeroF = hn::Zero(df);
  const VI zeroI = hn::Zero(di), oneI = hn::Set(di, 1);
  // In a segment (SampleTentativeCollisions' inner loop).
  const MF inSegment = hn::And(live, w.inSegment);
  const VF tauLeft = (w.segTMax - w.walkT) * w.segMaj;
  const MF usedUp = hn::And(inSegment, w.tau >= tauLeft);
  const MF arrive = hn::AndNot(usedUp, inSegment);
  w.tau = Sel(usedUp, w.tau - tauLeft, w.tau);
  w.walkT = Sel(arrive, w.walkT + w.tau / w.segMaj, w.walkT);
  w.inSegment = hn::AndNot(usedUp, w.inSegment);
  *arrived = arrive;

  // Between segments.
  const MF walking = hn::AndNot(w.inSegment, live);
  const MF going = hn::And(walking, w.itT < w.tEnd);
  const MF finished = hn::AndNot(going, walking);
  if (hn::AllFalse(df, going)) return finished;
  const VF maj = GatherF(grid.majorants, SelI(going, w.node, zeroI));
  const MF empty = hn::And(going, hn::Or(w.emptyClimb, maj <= zeroF));
  MF climbEmpty = hn::FirstN(df, 0), climb = climbEmpty, descend = climbEmpty;
  const MF nonEmpty = hn::AndNot(empty, going);
  if (octree) {
    const VI parentLevel = hn::Max(w.level - oneI, zeroI);
    const VI parentNode =
        LevelI(tables.offset, parentLevel) + hn::ShiftRight<1>(w.cell[0]) +
        LevelI(tables.res[0], parentLevel) *
            (hn::ShiftRight<1>(w.cell[1]) + LevelI(tables.res[1], parentLevel) * hn::ShiftRight<1>(w.cell[2]));
    const MF hasParent = hn::And(going, ToF(w.level > zeroI));
    const VF parentMaj = GatherF(grid.majorants, SelI(hasParent, parentNode, zeroI));
    // ClimbToHighestEmptyAncestor, a level an action.
    climbEmpty = hn::AndNot(parentMaj > zeroF, hn::And(empty, hasParent));
    const VF tau = maj * scale * LevelF(tables.worldWidth, w.level);
    const MF thin = hn::And(tau < hn::Set(df, kClimbOpticalThickness), hasParent);
    const VF parentTau = parentMaj * scale * LevelF(tables.worldWidth, parentLevel);
    climb = hn::And(hn::And(nonEmpty, thin), parentTau <= hn::Set(df, kDescendOpticalThickness));
    descend = hn::And(hn::AndNot(thin, nonEmpty),
                      hn::And(tau > hn::Set(df, kDescendOpticalThickness), ToF(w.level < hn::Set(di, grid.leafLevel))));
  }
  const MF stepEmpty = hn::AndNot(climbEmpty, empty);
  const MF emit = hn::AndNot(hn::Or(climb, descend), nonEmpty);
  const MF climbing = hn::Or(climb, climbEmpty);
  if (!hn::AllFalse(df, climbing)) Climb(tables, climbing, w);
  if (!hn::AllFalse(df, descend)) Descend(tables, grid.leafLevel, descend, w);
  w.emptyClimb = hn::Or(hn::AndNot(stepEmpty, w.emptyClimb), climbEmpty);
  const MF stepping = hn::Or(stepEmpty, emit);
  if (hn::AllFalse(df, stepping)) return finished;
  VI axis;
  const VF tExit = ExitDistance(w, &axis);
  const VF segTMin = w.itT, segMaj = maj * scale;
  const MF moved = Step(tables, stepping, axis, tExit, w);
  // A segment handed out, taken by the loop over segments.
  w.segments = SelI(emit, w.segments + oneI, w.segments);
  w.segMaj = Sel(emit, segMaj, w.segMaj);
  w.segTMax = Sel(emit, Sel(moved, tExit, w.tEnd), w.segTMax);
  const MF taken = hn::AndNot(segMaj <= zeroF, emit);
  w.walkT = Sel(taken, segTMin, w.walkT);
  w.inSegment = hn::Or(w.inSegment, taken);
  return finished;
}

// Delta tracking in lanes that are refilled from the queue `ids` as their
// walks collide or end: a walk stays in its lane from its first arrival to
// its real collision (a lane that stopped at each arrival was refilled
// four times a camera ray, and the loads and stores of the walks' state
// cost more than the lanes saved). With `Plain`, the extinction at the
// arrivals is looked up in the lanes (plain_extinction-inl.h); the choice
// is the caller's, one arrival at a time.
template <typename T, bool Plain>
void DeltaTrackLanes(const Classifier& classifier, const MajorantGridView& grid, GridTraversal traversal,
                     GridWalkLanes& walks, const uint32_t* ids, size_t count, ArrivalChoices& choices,
                     LaneCounters* counters) {
  LevelTables tables;
  for (int l = 0; l < kLevelTableSize; ++l) {
    const int used = l <= grid.leafLevel ? l : grid.leafLevel;
    tables.nodeSize[l] = grid.nodeSize[used];
    for (int a = 0; a < 3; ++a) tables.res[a][l] = grid.res[used][a];
    tables.offset[l] = (int32_t)grid.offset[used];
    tables.worldWidth[l] = grid.worldWidth[used];
  }
  for (int a = 0; a < 3; ++a) tables.cells[a] = (float)grid.cells[a];
  const std::optional<PlainScene<T>> scene =
      Plain ? std::optional<PlainScene<T>>(std::in_place, classifier) : std::nullopt;
  const bool octree = traversal == GridTraversal::Octree;
  const DF df;
  const DI di;
  const size_t n = hn::Lanes(df);
  const int32_t scratch = (int32_t)(walks.itT.size() - 1);
  const VF scale = hn::Set(df, 1.f);
  const VI oneI = hn::Set(di, 1), zeroI = hn::Zero(di), scratchI = hn::Set(di, scratch);
  constexpr size_t kMax = HWY_MAX_BYTES / sizeof(float);
  HWY_ALIGN int32_t laneId[kMax], flag[kMax];
  HWY_ALIGN float laneT[kMax], px[kMax], py[kMax], pz[kMax], laneMaj[kMax], laneSigma[kMax], laneTau[kMax];
  for (size_t k = 0; k < n; ++k) laneId[k] = scratch;
  VI id = hn::Load(di, laneId);
  Walks w;
  LoadWalks(walks, id, w);
  MF live = hn::FirstN(df, 0), free = hn::Not(live);
  size_t next = 0;
  LaneCounters c;
  for (;;) {
    // Refill when half the lanes are free: every lane's walk stored, the
    // free lanes given the next walks, all loaded again.
    if (next < count && hn::CountTrue(df, free) * 2 >= n) {
      StoreWalks(w, id, walks);
      hn::Store(id, di, laneId);
      hn::Store(SelI(free, oneI, zeroI), di, flag);
      for (size_t k = 0; k < n; ++k)
        if (flag[k]) laneId[k] = next < count ? (int32_t)ids[next++] : scratch;
      id = hn::Load(di, laneId);
      LoadWalks(walks, id, w);
      live = hn::Or(live, hn::And(free, ToF(hn::Not(id == scratchI))));
      free = hn::Not(live);
      ++c.refills;
    }
    if (hn::AllFalse(df, live)) break;
    ++c.actions;
    c.liveLanes += hn::CountTrue(df, live);
    MF arrived;
    const MF ended = Act(grid, tables, octree, scale, live, w, &arrived);
    MF real = hn::FirstN(df, 0);
    if (!hn::AllFalse(df, arrived)) {
      // The arrivals: their extinction in the lanes, the choices one at a time.
      const VF ax = w.o[0] + w.d[0] * w.walkT, ay = w.o[1] + w.d[1] * w.walkT, az = w.o[2] + w.d[2] * w.walkT;
      ++c.lookupRounds;
      c.lookups += hn::CountTrue(df, arrived);
      if constexpr (Plain) hn::Store(scene->Extinction(ax, ay, az), df, laneSigma);
      hn::Store(ax, df, px);
      hn::Store(ay, df, py);
      hn::Store(az, df, pz);
      hn::Store(w.walkT, df, laneT);
      hn::Store(w.segMaj, df, laneMaj);
      hn::Store(w.tau, df, laneTau);
      hn::Store(id, di, laneId);
      hn::Store(SelI(arrived, oneI, zeroI), di, flag);
      for (size_t k = 0; k < n; ++k) {
        if (!flag[k]) continue;
        flag[k] = choices.Real((uint32_t)laneId[k], laneT[k], Vec3{px[k], py[k], pz[k]}, laneMaj[k],
                               Plain ? &laneSigma[k] : nullptr, &laneTau[k])
                      ? 1
                      : 0;
      }
      real = ToF(hn::Load(di, flag) != zeroI);
      w.tau = Sel(hn::AndNot(real, arrived), hn::Load(df, laneTau), w.tau);
    }
    const MF done = hn::Or(ended, real);
    live = hn::AndNot(done, live);
    free = hn::Or(free, done);
  }
  StoreWalks(w, id, walks);  // the segments counted
  c.lanes = n;
  if (counters) *counters += c;
}

void DeltaTrackWalksLanes(const Classifier& classifier, const MajorantGridView& grid, GridTraversal traversal,
                          GridWalkLanes& walks, const uint32_t* ids, size_t count, ArrivalChoices& choices,
                          LaneCounters* counters) {
  auto run = [&](auto voxel, auto plain) {
    DeltaTrackLanes<decltype(voxel), decltype(plain)::value>(classifier, grid, traversal, walks, ids, count, choices,
                                                             counters);
  };
  if (!classifier.plain) return run(float(), std::false_type());
  switch (classifier.proxies[0].type) {
    case VoxelType::UInt8:
      return run(uint8_t(), std::true_type());
    case VoxelType::Int16:
      return run(int16_t(), std::true_type());
    case VoxelType::UInt16:
      return run(uint16_t(), std::true_type());
    default:
      return run(float(), std::true_type());
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace mmrtm
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mmrtm {

HWY_EXPORT(DeltaTrackWalksLanes);

void GridWalkLanes::Resize(size_t n) {
  for (int a = 0; a < 3; ++a)
    for (auto* v : {&o[a], &d[a], &invD[a], &tFace[a]}) v->assign(n + 1, 0.f);
  for (int a = 0; a < 3; ++a) cell[a].assign(n + 1, 0);
  for (auto* v : {&itT, &tEnd, &walkT, &tau, &segTMax, &segMaj}) v->assign(n + 1, 0.f);
  for (auto* v : {&level, &node, &inSegment, &emptyClimb, &segments}) v->assign(n + 1, 0);
}

void GridWalkLanes::Set(size_t i, const GridWalkState& s, float walkTau) {
  for (int a = 0; a < 3; ++a) {
    o[a][i] = s.o[a];
    d[a][i] = s.d[a];
    invD[a][i] = s.invD[a];
    tFace[a][i] = s.tFace[a];
    cell[a][i] = s.cell[a];
  }
  itT[i] = s.t;
  tEnd[i] = s.tEnd;
  level[i] = s.level;
  node[i] = (int32_t)s.node;
  walkT[i] = 0.f;
  tau[i] = walkTau;
  segTMax[i] = segMaj[i] = 0.f;
  inSegment[i] = emptyClimb[i] = segments[i] = 0;
}

bool GridWalkLanesFit(const MajorantGridView& grid) {
  const int l = grid.leafLevel;
  const int64_t nodes = grid.offset[l] + (int64_t)grid.res[l][0] * grid.res[l][1] * grid.res[l][2];
  return nodes < ((int64_t)1 << 31);
}

bool PlainLookupsFit(const Classifier& classifier) {
  if (!classifier.plain) return true;
  const VolumeView& v = classifier.proxies[0];
  const int64_t bytes = (int64_t)v.nx * v.ny * v.nz * VoxelTypeSize(v.type);
  return bytes >= 4 && bytes < ((int64_t)1 << 31);  // plain_extinction.h
}

void DeltaTrackWalks(const Classifier& classifier, const MajorantGridView& grid, GridTraversal traversal,
                     GridWalkLanes& walks, const uint32_t* ids, size_t count, ArrivalChoices& choices,
                     LaneCounters* counters) {
  HWY_DYNAMIC_DISPATCH(DeltaTrackWalksLanes)
  (classifier, grid, traversal, walks, ids, count, choices, counters);
}

}  // namespace mmrtm
#endif  // HWY_ONCE
