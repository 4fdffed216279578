// A plain scene's extinction in lanes: the voxel loads, the trilinear or
// nearest lookup and the density TF, through the per-lane templates of
// include/mmrtm instantiated for Highway vectors (plain_extinction.h says
// what it computes). Included once per Highway target, inside
// HWY_NAMESPACE's files (plain_extinction.cpp, grid_walk_lanes.cpp), hence
// the toggled guard instead of #pragma once.
#if defined(MMRTM_SIMD_PLAIN_EXTINCTION_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef MMRTM_SIMD_PLAIN_EXTINCTION_INL_H_
#undef MMRTM_SIMD_PLAIN_EXTINCTION_INL_H_
#else
#define MMRTM_SIMD_PLAIN_EXTINCTION_INL_H_
#endif

#include <hwy/highway.h>

#include "mmrtm/classifier.h"
#include "mmrtm/planted_defect.h"
#include "simd/highway_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace mmrtm {
namespace HWY_NAMESPACE {

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using Lanes = HighwayLanes<DF>;
using Float = hn::Vec<DF>;
using Int = hn::Vec<DI>;
using Mask = Lanes::Mask;

// Voxel loads. A float voxel is one gather. Narrower voxels have no gather
// of their own: a 32-bit word is gathered at the voxel's byte offset, moved
// back where it would pass the buffer's end (to `lastWord`, the buffer's
// size - 4), and the voxel is shifted out of it. Adjacent voxels along x sit
// in the same word, so one gather gives a cell's two x corners.
template <typename T>
struct VoxelGather {
  const T* data;
  Int lastWord;

  // The voxel `shiftBits` bits into `word`, sign-extended for int16.
  static inline Float FromWord(Int word, Int shiftBits) {
    constexpr int kBits = 8 * (int)sizeof(T);
    const auto left = hn::BitCast(DU(), hn::Set(DI(), 32 - kBits) - shiftBits);
    const Int top = hn::BitCast(DI(), hn::BitCast(DU(), word) << left);  // the voxel in the top bits
    if constexpr (T(-1) < T(0)) return hn::ConvertTo(DF(), hn::ShiftRight<32 - kBits>(top));
    return hn::ConvertTo(DF(), hn::BitCast(DI(), hn::ShiftRight<32 - kBits>(hn::BitCast(DU(), top))));
  }

  // Voxel `index` and, when `adjacent`, voxel index + 1 (else the same one).
  inline void Pair(Int index, bool adjacent, Float* first, Float* second) const {
    if constexpr (sizeof(T) == 4) {
      *first = hn::GatherIndex(DF(), reinterpret_cast<const float*>(data), index);
      *second =
          adjacent ? hn::GatherIndex(DF(), reinterpret_cast<const float*>(data), index + hn::Set(DI(), 1)) : *first;
    } else {
      const Int byte = index * hn::Set(DI(), (int)sizeof(T));
      const Int start = hn::Min(byte, lastWord);
      const Int word = hn::GatherOffset(DI(), reinterpret_cast<const int32_t*>(data), start);
      const Int shiftBits = hn::ShiftLeft<3>(byte - start);
      *first = FromWord(word, shiftBits);
      *second = adjacent ? FromWord(word, shiftBits + hn::Set(DI(), 8 * (int)sizeof(T))) : *first;
    }
  }
  inline Float One(Int index) const {
    Float value, unused;
    Pair(index, false, &value, &unused);
    return value;
  }
};

// VolumeView::SampleIndex in lanes.
template <typename T>
inline Float SampleIndexLanes(const VolumeView& v, const VoxelGather<T>& voxels, Float px, Float py, Float pz) {
  const Int nx = hn::Set(DI(), v.nx), slice = hn::Set(DI(), (int32_t)v.sliceStride);
  if (v.interpolation == Interpolation::Nearest) {
    const Int x = NearestAxis<Lanes>({px}, v.last[0]).raw, y = NearestAxis<Lanes>({py}, v.last[1]).raw;
    const Int z = NearestAxis<Lanes>({pz}, v.last[2]).raw;
    return voxels.One(x + y * nx + z * slice);
  }
  Lanes::Int x0, y0, z0;
  Lanes::Float tx, ty, tz;
  TrilinearAxis<Lanes>({px}, v.last[0], v.lastCell[0], &x0, &tx);
  TrilinearAxis<Lanes>({py}, v.last[1], v.lastCell[1], &y0, &ty);
  TrilinearAxis<Lanes>({pz}, v.last[2], v.lastCell[2], &z0, &tz);
  const Int c = x0.raw + y0.raw * nx + z0.raw * slice;
  const Int dy = hn::Set(DI(), (int32_t)v.cornerStep[1]), dz = hn::Set(DI(), (int32_t)v.cornerStep[2]);
  const bool adjacent = v.cornerStep[0] != 0;
  Float c000, c100, c010, c110, c001, c101, c011, c111;
  voxels.Pair(c, adjacent, &c000, &c100);
  voxels.Pair(c + dy, adjacent, &c010, &c110);
  voxels.Pair(c + dz, adjacent, &c001, &c101);
  voxels.Pair(c + dy + dz, adjacent, &c011, &c111);
  return InterpolateCell<Lanes>({c000}, {c100}, {c010}, {c110}, {c001}, {c101}, {c011}, {c111}, tx, ty, tz).raw;
}

// TransferFunctionView::Evaluate of a one-channel CCTF in lanes: the ends
// as Evaluate's first two lines, the inside by the shared segment search.
inline Float CurveLanes(const TransferFunctionView& tf, Float x) {
  const Float firstValue = hn::Set(DF(), tf.values[0]);
  if (tf.count == 1) return firstValue;
  const Mask first = x <= hn::Set(DF(), tf.keys[0]);
  const Mask last = x >= hn::Set(DF(), tf.keys[tf.count - 1]);
  const Float endValue = hn::IfThenElse(first, firstValue, hn::Set(DF(), tf.values[(tf.count - 1) * tf.channels]));
  const Mask end = hn::Or(first, last);
  if (hn::AllTrue(DF(), end)) return endValue;
  // Lanes at an end may have any segment in [-1, count - 1]: kept in
  // bounds for the gathers, and their value is not taken.
  Lanes::Int lo = tf.CurveSegment<Lanes>({x});
  lo.raw = hn::Max(hn::Min(lo.raw, hn::Set(DI(), tf.count - 2)), hn::Zero(DI()));
  const Float inside = tf.CurveChannel<Lanes>(tf.CurveFraction<Lanes>({x}, lo), lo, 0).raw;
  return hn::IfThenElse(end, endValue, inside);
}

// The density TF's value in lanes: a CCTF by CurveLanes, other types one
// lane at a time through Evaluate.
inline Float DensityTFLanes(const TransferFunctionView& tf, Float x) {
  if (tf.type == TFType::CCTF) return CurveLanes(tf, x);
  HWY_ALIGN float lanes[HWY_MAX_BYTES / sizeof(float)];
  hn::Store(x, DF(), lanes);
  for (size_t i = 0; i < hn::Lanes(DF()); ++i) tf.Evaluate(lanes[i], &lanes[i]);
  return hn::Load(DF(), lanes);
}

// What a plain scene's extinction reads, for one voxel type.
template <typename T>
struct PlainScene {
  const Classifier& classifier;
  const VolumeView& volume;
  const TransferFunctionView& tf;
  VoxelGather<T> voxels;

  explicit PlainScene(const Classifier& c)
      : classifier(c),
        volume(c.proxies[0]),
        tf(c.PlainDensityTF()),
        voxels{static_cast<const T*>(volume.data),
               hn::Set(DI(), (int32_t)((int64_t)volume.nx * volume.ny * volume.nz * (int64_t)sizeof(T) - 4))} {}

  // The extinction at index points (px, py, pz): Classifier::Classify's;
  // `value`, when given, gets the volume's value there (the
  // classification's proxy sample).
  inline Float Extinction(Float px, Float py, Float pz, Float* value = nullptr) const {
    const Float sample = SampleIndexLanes(volume, voxels, px, py, pz);
    if (value) *value = sample;
    const Float sigma_t = classifier.PlainExtinction<Lanes>({DensityTFLanes(tf, sample)}).raw;
    return Planted(Defect::SimdExtinction) ? sigma_t * hn::Set(DF(), 0.98f) : sigma_t;
  }
};

}  // namespace HWY_NAMESPACE
}  // namespace mmrtm
HWY_AFTER_NAMESPACE();

#endif  // MMRTM_SIMD_PLAIN_EXTINCTION_INL_H_
