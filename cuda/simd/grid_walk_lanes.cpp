// Compiled once per Highway target (foreach_target.h re-includes this file),
// with -ffp-contract=off (cuda/CMakeLists.txt), so that every operation
// rounds as the scalar walk's does. The scalar walk, mirrored here operation
// by operation, is GridMajorantIterator (mmrtm/majorant_grid_view.h) and
// the loop of SampleTentativeCollisions (mmrtm/tracking.h) for delta tracking.
#include "grid_walk_lanes.h"

#include <cstring>
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
  if (n >= kMaxGridLevels) return hn::TableLookupLanes(hn::LoadU(d, table), hn::IndicesFromVec(d, level));
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
  MF inSegment;
};

// A level's numbers in each lane, looked up once an action: the node size
// (voxel cells) and the grid's resolution per axis.
struct LevelNumbers {
  VF size;
  VI res[3];
};
HWY_INLINE LevelNumbers NumbersOf(const LevelTables& tables, VI level) {
  return {hn::ConvertTo(DF(), LevelI(tables.nodeSize, level)),
          {LevelI(tables.res[0], level), LevelI(tables.res[1], level), LevelI(tables.res[2], level)}};
}

// GridMajorantIterator's step_[a]: +1, -1 or 0, the direction d.
HWY_INLINE VI StepOf(VF d) {
  const VI up = hn::Set(DI(), 1), down = hn::Set(DI(), -1), zero = hn::Zero(DI());
  return hn::IfThenElse(hn::RebindMask(DI(), d > hn::Zero(DF())), up,
                        hn::IfThenElse(hn::RebindMask(DI(), d < hn::Zero(DF())), down, zero));
}

// GridMajorantIterator::FaceAhead along one axis, given that axis' origin,
// direction, inverse direction, cell, and the grid's cells (its end).
HWY_INLINE VF FaceAhead(VF o, VF d, VF invD, VI cell, VF cells, VF size) {
  const VI one = hn::Set(DI(), 1), zero = hn::Zero(DI()), step = StepOf(d);
  const VI ahead = cell + hn::IfThenElse(step > zero, one, zero);
  const VF plane = hn::ConvertTo(DF(), ahead) * size;
  // tClip_[a]: where the ray leaves the grid's last cell ahead.
  const VF inf = hn::Set(DF(), kInfinity);
  const VF tClip = hn::IfThenElse(d > hn::Zero(DF()), (cells - o) * invD, inf);
  const VF t = MinF((plane - o) * invD, tClip);
  return hn::IfThenElse(ToF(step == zero), inf, t);
}

// GridMajorantIterator::EnterLevel in the lanes of `m` (their level and
// cells set already; `at`: that level's numbers).
HWY_INLINE void EnterLevel(const LevelTables& tables, const LevelNumbers& at, MF m, Walks& w) {
  const VI node = LevelI(tables.offset, w.level) + w.cell[0] + at.res[0] * (w.cell[1] + at.res[1] * w.cell[2]);
  w.node = SelI(m, node, w.node);
  for (int a = 0; a < 3; ++a)
    w.tFace[a] =
        Sel(m, FaceAhead(w.o[a], w.d[a], w.invD[a], w.cell[a], hn::Set(DF(), tables.cells[a]), at.size), w.tFace[a]);
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

// GridMajorantIterator::Step in the lanes of `m` (`at`: their level's
// numbers); the lanes that moved to a neighbour (the others' walks end:
// itT = tEnd). A lane crosses one face: that axis' numbers are picked per
// lane and its crossing time computed once.
HWY_INLINE MF Step(const LevelTables& tables, const LevelNumbers& at, MF m, VI axis, VF tExit, Walks& w) {
  w.itT = Sel(m, tExit, w.itT);
  const MF fail = hn::And(m, hn::Or(ToF(axis < hn::Zero(DI())), tExit >= w.tEnd));
  const MF go = hn::AndNot(fail, m);
  MF along[3];
  for (int a = 0; a < 3; ++a) along[a] = hn::And(go, ToF(axis == hn::Set(DI(), a)));
  auto pickF = [&](const VF* v) { return Sel(along[0], v[0], Sel(along[1], v[1], v[2])); };
  auto pickI = [&](const VI* v) { return SelI(along[0], v[0], SelI(along[1], v[1], v[2])); };
  const VF o = pickF(w.o), d = pickF(w.d), invD = pickF(w.invD);
  const VF cellsPerAxis[3] = {hn::Set(DF(), tables.cells[0]), hn::Set(DF(), tables.cells[1]),
                              hn::Set(DF(), tables.cells[2])};
  const VI stride[3] = {hn::Set(DI(), 1), at.res[0], at.res[0] * at.res[1]};
  const VI step = StepOf(d);
  const VI next = pickI(w.cell) + step;
  const MF out = ToF(hn::Or(next < hn::Zero(DI()), hn::Not(next < pickI(at.res))));
  const MF in = hn::AndNot(out, go);
  for (int a = 0; a < 3; ++a) w.cell[a] = SelI(along[a], next, w.cell[a]);
  w.node = SelI(in, w.node + step * pickI(stride), w.node);
  const VF tFace = FaceAhead(o, d, invD, next, pickF(cellsPerAxis), at.size);
  for (int a = 0; a < 3; ++a) w.tFace[a] = Sel(hn::And(in, along[a]), tFace, w.tFace[a]);
  w.itT = Sel(hn::Or(fail, hn::And(go, out)), w.tEnd, w.itT);
  return in;
}

// A change of level in the lanes of `m`: up one level in those of `climb`
// (GridMajorantIterator::Climb, and a step of ClimbToHighestEmptyAncestor),
// into the child the ray is in at itT in the others
// (GridMajorantIterator::Descend); then EnterLevel.
HWY_INLINE void ChangeLevel(const LevelTables& tables, int leafLevel, MF m, MF climb, Walks& w) {
  const VI one = hn::Set(DI(), 1), zero = hn::Zero(DI());
  const VI child = hn::Min(w.level + one, hn::Set(DI(), leafLevel));
  const VI level = SelI(climb, w.level - one, child);
  const LevelNumbers at = NumbersOf(tables, level);
  for (int a = 0; a < 3; ++a) {
    const VF p = w.o[a] + w.d[a] * w.itT;
    const VI twice = w.cell[a] + w.cell[a];
    const VF mid = hn::ConvertTo(DF(), twice + one) * at.size;
    const VF rel = p - mid;
    const MF nearMid = hn::Abs(rel) <= hn::Set(DF(), 1e-4f) * at.size;  // ties go to the side the ray heads to
    const MF upper = hn::Or(hn::And(nearMid, w.d[a] > hn::Zero(DF())), hn::AndNot(nearMid, rel > hn::Zero(DF())));
    const VI cell = twice + hn::IfThenElse(hn::RebindMask(DI(), upper), one, zero);
    const VI descended = hn::Min(hn::Max(cell, zero), at.res[a] - one);
    w.cell[a] = SelI(m, SelI(climb, hn::ShiftRight<1>(w.cell[a]), descended), w.cell[a]);
  }
  w.level = SelI(m, level, w.level);
  EnterLevel(tables, at, m, w);
}

// Starts the walks `id` in the lanes of `m` (the others keep theirs).
HWY_INLINE void LoadWalks(const GridWalkLanes& walks, MF m, VI id, Walks& w) {
  auto loadF = [&](const std::vector<float>& v, VF& lane) { lane = Sel(m, GatherF(v.data(), id), lane); };
  auto loadI = [&](const std::vector<int32_t>& v, VI& lane) { lane = SelI(m, GatherI(v.data(), id), lane); };
  for (int a = 0; a < 3; ++a) {
    loadF(walks.o[a], w.o[a]);
    loadF(walks.d[a], w.d[a]);
    loadF(walks.invD[a], w.invD[a]);
    loadF(walks.tFace[a], w.tFace[a]);
    loadI(walks.cell[a], w.cell[a]);
  }
  loadF(walks.itT, w.itT);
  loadF(walks.tEnd, w.tEnd);
  loadF(walks.tau, w.tau);
  loadI(walks.level, w.level);
  loadI(walks.node, w.node);
  // No segment yet.
  w.walkT = Sel(m, hn::Zero(DF()), w.walkT);
  w.segTMax = Sel(m, hn::Zero(DF()), w.segTMax);
  w.segMaj = Sel(m, hn::Zero(DF()), w.segMaj);
  w.segments = SelI(m, hn::Zero(DI()), w.segments);
  w.inSegment = hn::AndNot(m, w.inSegment);
}

// SampleTentativeCollisions' inner loop, once, in the lanes of `m` (in a
// segment): the next arrival in the segment, or the segment used up (its
// optical depth carried on). Returns the lanes at an arrival.
HWY_INLINE MF InSegment(MF m, Walks& w) {
  const VF tauLeft = (w.segTMax - w.walkT) * w.segMaj;
  const MF usedUp = hn::And(m, w.tau >= tauLeft);
  const MF arrive = hn::AndNot(usedUp, m);
  w.tau = Sel(usedUp, w.tau - tauLeft, w.tau);
  w.walkT = Sel(arrive, w.walkT + w.tau / w.segMaj, w.walkT);
  w.inSegment = hn::AndNot(usedUp, w.inSegment);
  return arrive;
}

// GridMajorantIterator::ClimbToHighestEmptyAncestor in the lanes of `m`,
// whose parent the caller found empty: up while the next parent is empty
// too, then EnterLevel once.
HWY_INLINE void ClimbEmpty(const MajorantGridView& grid, const LevelTables& tables, MF m, Walks& w) {
  const VI one = hn::Set(DI(), 1), zero = hn::Zero(DI());
  MF up = m;
  while (!hn::AllFalse(DF(), up)) {
    w.level = SelI(up, w.level - one, w.level);
    for (int a = 0; a < 3; ++a) w.cell[a] = SelI(up, hn::ShiftRight<1>(w.cell[a]), w.cell[a]);
    const MF climbing = hn::And(up, ToF(w.level > zero));
    if (hn::AllFalse(DF(), climbing)) break;
    const VI parentLevel = hn::Max(w.level - one, zero);
    const VI parentNode =
        LevelI(tables.offset, parentLevel) + hn::ShiftRight<1>(w.cell[0]) +
        LevelI(tables.res[0], parentLevel) *
            (hn::ShiftRight<1>(w.cell[1]) + LevelI(tables.res[1], parentLevel) * hn::ShiftRight<1>(w.cell[2]));
    up = hn::AndNot(GatherF(grid.majorants, SelI(climbing, parentNode, zero)) > hn::Zero(DF()), climbing);
  }
  EnterLevel(tables, NumbersOf(tables, w.level), m, w);
}

// One action of every lane in `live`: an arrival in its segment, or, with
// the segment used up or between segments, the grid walk's next segment as
// GridMajorantIterator::Next finds it (its climbs and descents, then one
// step: out of an empty node, or past the segment handed out) and the
// first arrival in that segment; or the walk's end. A lane whose empty step
// or segment leaves it without an arrival goes on in the next action.
// Returns the lanes whose walk ended; `arrived`: the lanes at an arrival.
HWY_INLINE MF Act(const MajorantGridView& grid, const LevelTables& tables, bool octree, VF scale, MF live, Walks& w,
                  MF* arrived) {
  const DF df;
  const DI di;
  const VF zeroF = hn::Zero(df);
  const VI zeroI = hn::Zero(di), oneI = hn::Set(di, 1);
  *arrived = InSegment(hn::And(live, w.inSegment), w);

  // Between segments: Next's loop, a decision a round; the lanes that
  // climb or descend decide again at their new level.
  const MF walking = hn::AndNot(w.inSegment, live);
  const MF going = hn::And(walking, w.itT < w.tEnd);
  const MF finished = hn::AndNot(going, walking);
  if (hn::AllFalse(df, going)) return finished;
  VF maj = zeroF;
  MF deciding = going, empty = hn::FirstN(df, 0), emit = empty;
  for (;;) {
    maj = Sel(deciding, GatherF(grid.majorants, SelI(deciding, w.node, zeroI)), maj);
    const MF emptyHere = hn::And(deciding, maj <= zeroF);
    const MF nonEmpty = hn::AndNot(emptyHere, deciding);
    MF climb = hn::FirstN(df, 0), descend = climb;
    if (octree) {
      const VI parentLevel = hn::Max(w.level - oneI, zeroI);
      const VI parentNode =
          LevelI(tables.offset, parentLevel) + hn::ShiftRight<1>(w.cell[0]) +
          LevelI(tables.res[0], parentLevel) *
              (hn::ShiftRight<1>(w.cell[1]) + LevelI(tables.res[1], parentLevel) * hn::ShiftRight<1>(w.cell[2]));
      const MF hasParent = hn::And(deciding, ToF(w.level > zeroI));
      const VF parentMaj = GatherF(grid.majorants, SelI(hasParent, parentNode, zeroI));
      const VF tau = maj * scale * LevelF(tables.worldWidth, w.level);
      const MF thin = hn::And(tau < hn::Set(df, kClimbOpticalThickness), hasParent);
      const VF parentTau = parentMaj * scale * LevelF(tables.worldWidth, parentLevel);
      climb = hn::And(hn::And(nonEmpty, thin), parentTau <= hn::Set(df, kDescendOpticalThickness));
      descend = hn::And(hn::AndNot(thin, nonEmpty), hn::And(tau > hn::Set(df, kDescendOpticalThickness),
                                                            ToF(w.level < hn::Set(di, grid.leafLevel))));
      const MF climbEmpty = hn::AndNot(parentMaj > zeroF, hn::And(emptyHere, hasParent));
      if (!hn::AllFalse(df, climbEmpty)) ClimbEmpty(grid, tables, climbEmpty, w);
    }
    empty = hn::Or(empty, emptyHere);
    deciding = hn::Or(climb, descend);
    emit = hn::Or(emit, hn::AndNot(deciding, nonEmpty));
    if (hn::AllFalse(df, deciding)) break;
    ChangeLevel(tables, grid.leafLevel, deciding, climb, w);
  }

  // The step, at the level each lane stays on.
  const MF stepping = hn::Or(empty, emit);
  VI axis;
  const VF tExit = ExitDistance(w, &axis);
  const VF segTMin = w.itT, segMaj = maj * scale;
  const MF moved = Step(tables, NumbersOf(tables, w.level), stepping, axis, tExit, w);
  // A segment handed out, taken by the loop over segments, and its first
  // arrival.
  w.segments = SelI(emit, w.segments + oneI, w.segments);
  w.segMaj = Sel(emit, segMaj, w.segMaj);
  w.segTMax = Sel(emit, Sel(moved, tExit, w.tEnd), w.segTMax);
  const MF taken = hn::AndNot(segMaj <= zeroF, emit);
  w.walkT = Sel(taken, segTMin, w.walkT);
  w.inSegment = hn::Or(w.inSegment, taken);
  *arrived = hn::Or(*arrived, InSegment(taken, w));
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
  HWY_ALIGN float laneT[kMax], px[kMax], py[kMax], pz[kMax], laneMaj[kMax], laneSigma[kMax], laneValue[kMax],
      laneTau[kMax];
  for (size_t k = 0; k < n; ++k) laneId[k] = scratch;
  VI id = hn::Load(di, laneId);
  Walks w;
  w.inSegment = hn::FirstN(df, 0);
  LoadWalks(walks, hn::Not(w.inSegment), id, w);
  MF live = hn::FirstN(df, 0), free = hn::Not(live);
  size_t next = 0;
  LaneCounters c;
  for (;;) {
    // Refill when half the lanes are free: the free lanes given the next
    // walks. A walk's state stays in its lane until it ends; of an ended
    // walk only its segment count is stored.
    if (next < count && hn::CountTrue(df, free) * 2 >= n) {
      hn::Store(SelI(free, oneI, zeroI), di, flag);
      for (size_t k = 0; k < n; ++k)
        if (flag[k]) laneId[k] = next < count ? (int32_t)ids[next++] : scratch;
      id = hn::Load(di, laneId);
      LoadWalks(walks, free, SelI(free, id, scratchI), w);
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
      if constexpr (Plain) {
        VF value;
        hn::Store(scene->Extinction(ax, ay, az, &value), df, laneSigma);
        hn::Store(value, df, laneValue);
      }
      hn::Store(ax, df, px);
      hn::Store(ay, df, py);
      hn::Store(az, df, pz);
      hn::Store(w.walkT, df, laneT);
      hn::Store(w.segMaj, df, laneMaj);
      hn::Store(w.tau, df, laneTau);  // laneId holds id since the last refill
      uint8_t arrivedBits[8] = {};
      hn::StoreMaskBits(df, arrived, arrivedBits);
      uint64_t pending;
      std::memcpy(&pending, arrivedBits, sizeof pending);
      hn::Store(zeroI, di, flag);
      Classification plain;  // a plain scene's: its fields other than the lanes' numbers stay as made
      for (; pending; pending &= pending - 1) {
        const int k = __builtin_ctzll(pending);
        if constexpr (Plain) Classifier::SetPlainClassification(laneValue[k], laneSigma[k], &plain);
        flag[k] = choices.Real((uint32_t)laneId[k], laneT[k], Vec3{px[k], py[k], pz[k]}, laneMaj[k],
                               Plain ? &plain : nullptr, &laneTau[k])
                      ? 1
                      : 0;
      }
      real = ToF(hn::Load(di, flag) != zeroI);
      w.tau = Sel(hn::AndNot(real, arrived), hn::Load(df, laneTau), w.tau);
    }
    const MF done = hn::Or(ended, real);
    if (!hn::AllFalse(df, done)) hn::ScatterIndex(w.segments, di, walks.segments.data(), SelI(done, id, scratchI));
    live = hn::AndNot(done, live);
    free = hn::Or(free, done);
  }
  c.lanes = n;
  if (counters) *counters += c;
}

// GridMajorantIterator's constructor for walks [0, count) (contiguous, in
// whole vectors: the walks' arrays are padded), from index rays (o, d)
// over [t0, t1): at the leaf each ray starts in.
void StartWalksLanes(const MajorantGridView& grid, const float* const* o, const float* const* d, const float* t0,
                     const float* t1, size_t count, GridWalkLanes& walks) {
  const DF df;
  const DI di;
  const size_t n = hn::Lanes(df);
  const int leaf = grid.leafLevel;
  const VF zeroF = hn::Zero(df), oneF = hn::Set(df, 1.f);
  const VF size = hn::Set(df, (float)grid.nodeSize[leaf]);
  for (size_t i = 0; i < count; i += n) {
    Walks w;
    for (int a = 0; a < 3; ++a) {
      w.o[a] = hn::LoadU(df, o[a] + i);
      w.d[a] = hn::LoadU(df, d[a] + i);
      w.invD[a] = hn::IfThenElse(w.d[a] != zeroF, oneF / w.d[a], zeroF);
    }
    w.itT = hn::LoadU(df, t0 + i);
    w.tEnd = hn::LoadU(df, t1 + i);
    w.level = hn::Set(di, leaf);
    for (int a = 0; a < 3; ++a) {
      const VF x = (w.o[a] + w.d[a] * w.itT) / size;  // FloorClamped(x, res - 1)
      const VI hi = hn::Set(di, grid.res[leaf][a] - 1);
      const VI inside = hn::IfThenElse(hn::RebindMask(di, x < hn::ConvertTo(df, hi)), hn::ConvertTo(di, x), hi);
      w.cell[a] = hn::IfThenElse(hn::RebindMask(di, x >= oneF), inside, hn::Zero(di));
    }
    // EnterLevel.
    const VI node = hn::Set(di, (int32_t)grid.offset[leaf]) + w.cell[0] +
                    hn::Set(di, grid.res[leaf][0]) * (w.cell[1] + hn::Set(di, grid.res[leaf][1]) * w.cell[2]);
    for (int a = 0; a < 3; ++a) {
      const VF tFace = FaceAhead(w.o[a], w.d[a], w.invD[a], w.cell[a], hn::Set(df, (float)grid.cells[a]), size);
      hn::StoreU(w.o[a], df, walks.o[a].data() + i);
      hn::StoreU(w.d[a], df, walks.d[a].data() + i);
      hn::StoreU(w.invD[a], df, walks.invD[a].data() + i);
      hn::StoreU(tFace, df, walks.tFace[a].data() + i);
      hn::StoreU(w.cell[a], di, walks.cell[a].data() + i);
    }
    hn::StoreU(w.itT, df, walks.itT.data() + i);
    hn::StoreU(w.tEnd, df, walks.tEnd.data() + i);
    hn::StoreU(w.level, di, walks.level.data() + i);
    hn::StoreU(node, di, walks.node.data() + i);
    hn::StoreU(hn::Zero(di), di, walks.segments.data() + i);
  }
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
HWY_EXPORT(StartWalksLanes);

namespace {
// Whole vectors past the last walk (StartWalks): the widest vector of any
// target (SVE's 2048 bits; HWY_MAX_BYTES here is the last target's).
constexpr size_t kPad = 256 / sizeof(float);
}  // namespace

void GridWalkLanes::Resize(size_t n) {
  const size_t slots = n + kPad + 1;
  if (itT.size() < slots) {
    for (int a = 0; a < 3; ++a)
      for (auto* v : {&o[a], &d[a], &invD[a], &tFace[a]}) v->resize(slots);
    for (int a = 0; a < 3; ++a) cell[a].resize(slots);
    for (auto* v : {&itT, &tEnd, &tau}) v->resize(slots);
    for (auto* v : {&level, &node, &segments}) v->resize(slots);
  }
  // The scratch slot (the last): an ended walk at level 0.
  Set(itT.size() - 1, GridWalkState{}, 0.f);
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
  tau[i] = walkTau;
  level[i] = s.level;
  node[i] = (int32_t)s.node;
  segments[i] = 0;
}

void StartWalks(const MajorantGridView& grid, const float* const o[3], const float* const d[3], const float* t0,
                const float* t1, size_t count, GridWalkLanes& walks) {
  MMRTM_DCHECK(walks.itT.size() >= count + kPad + 1);
  HWY_DYNAMIC_DISPATCH(StartWalksLanes)(grid, o, d, t0, t1, count, walks);
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
