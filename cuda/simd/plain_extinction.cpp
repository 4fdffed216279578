// Compiled once per Highway target (foreach_target.h re-includes this file),
// with -ffp-contract=off (cuda/CMakeLists.txt): the scalar path is compiled
// without fused multiply-adds on x86-64, so the lanes round exactly as it
// does and the results are the same bits.
#include "plain_extinction.h"

#include "mmrtm/planted_defect.h"

#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "simd/plain_extinction.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

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

template <typename T>
inline void PlainExtinctionOfType(const Classifier& classifier, const float* x, const float* y, const float* z,
                                  size_t count, float* sigma_t) {
  const VolumeView& volume = classifier.proxies[0];
  const TransferFunctionView& tf = classifier.PlainDensityTF();
  const int64_t bytes = (int64_t)volume.nx * volume.ny * volume.nz * (int64_t)sizeof(T);
  const VoxelGather<T> voxels{static_cast<const T*>(volume.data), hn::Set(DI(), (int32_t)(bytes - 4))};
  const DF df;
  const size_t n = hn::Lanes(df);
  auto extinction = [&](Float px, Float py, Float pz) {
    return classifier.PlainExtinction<Lanes>({DensityTFLanes(tf, SampleIndexLanes(volume, voxels, px, py, pz))}).raw;
  };
  size_t i = 0;
  for (; i + n <= count; i += n)
    hn::StoreU(extinction(hn::LoadU(df, x + i), hn::LoadU(df, y + i), hn::LoadU(df, z + i)), df, sigma_t + i);
  if (i == count) return;
  // The last points, in lanes padded with the first of them.
  HWY_ALIGN float px[HWY_MAX_BYTES / sizeof(float)], py[HWY_MAX_BYTES / sizeof(float)],
      pz[HWY_MAX_BYTES / sizeof(float)];
  for (size_t k = 0; k < n; ++k) {
    const size_t from = i + k < count ? i + k : i;
    px[k] = x[from];
    py[k] = y[from];
    pz[k] = z[from];
  }
  hn::Store(extinction(hn::Load(df, px), hn::Load(df, py), hn::Load(df, pz)), df, px);
  std::memcpy(sigma_t + i, px, (count - i) * sizeof(float));
}

HWY_FLATTEN void PlainExtinctionLanes(const Classifier& classifier, const float* x, const float* y, const float* z,
                                      size_t count, float* sigma_t) {
  switch (classifier.proxies[0].type) {
    case VoxelType::UInt8:
      return PlainExtinctionOfType<uint8_t>(classifier, x, y, z, count, sigma_t);
    case VoxelType::Int16:
      return PlainExtinctionOfType<int16_t>(classifier, x, y, z, count, sigma_t);
    case VoxelType::UInt16:
      return PlainExtinctionOfType<uint16_t>(classifier, x, y, z, count, sigma_t);
    default:
      return PlainExtinctionOfType<float>(classifier, x, y, z, count, sigma_t);
  }
}

const char* TargetNameLanes() { return hwy::TargetName(HWY_TARGET); }
size_t LaneCountLanes() { return hn::Lanes(DF()); }

}  // namespace HWY_NAMESPACE
}  // namespace mmrtm
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mmrtm {

HWY_EXPORT(PlainExtinctionLanes);
HWY_EXPORT(TargetNameLanes);
HWY_EXPORT(LaneCountLanes);

void PlainExtinctionSimd(const Classifier& classifier, const float* x, const float* y, const float* z, size_t count,
                         float* sigma_t) {
  MMRTM_DCHECK(classifier.plain);
  const VolumeView& v = classifier.proxies[0];
  const int64_t bytes = (int64_t)v.nx * v.ny * v.nz * VoxelTypeSize(v.type);
  // The gathers take 32-bit byte offsets, and a narrow voxel's word is 4
  // bytes of the buffer.
  if (bytes < 4 || bytes >= ((int64_t)1 << 31)) return PlainExtinctionScalar(classifier, x, y, z, count, sigma_t);
  HWY_DYNAMIC_DISPATCH(PlainExtinctionLanes)(classifier, x, y, z, count, sigma_t);
  if (Planted(Defect::SimdExtinction))
    for (size_t i = 0; i < count; ++i) sigma_t[i] *= 0.98f;
}

void PlainExtinctionScalar(const Classifier& classifier, const float* x, const float* y, const float* z, size_t count,
                           float* sigma_t) {
  for (size_t i = 0; i < count; ++i) {
    // A plain scene's classification reads only the index point (the world
    // point serves cropping, which a plain scene has not).
    const Vec3 index0{x[i], y[i], z[i]};
    sigma_t[i] = classifier.Classify(index0, index0).sigma_t;
  }
}

const char* PlainExtinctionTarget() { return HWY_DYNAMIC_DISPATCH(TargetNameLanes)(); }
size_t PlainExtinctionLaneCount() { return HWY_DYNAMIC_DISPATCH(LaneCountLanes)(); }

}  // namespace mmrtm
#endif  // HWY_ONCE
