// Compiled once per Highway target (foreach_target.h re-includes this file),
// with -ffp-contract=off (cuda/CMakeLists.txt): the scalar path is compiled
// without fused multiply-adds on x86-64, so the lanes round exactly as it
// does and the results are the same bits.
#include "plain_extinction.h"

#include <cstring>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "simd/plain_extinction.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "simd/plain_extinction-inl.h"

HWY_BEFORE_NAMESPACE();
namespace mmrtm {
namespace HWY_NAMESPACE {

template <typename T>
inline void PlainExtinctionOfType(const Classifier& classifier, const float* x, const float* y, const float* z,
                                  size_t count, float* sigma_t) {
  const PlainScene<T> scene(classifier);
  const DF df;
  const size_t n = hn::Lanes(df);
  auto extinction = [&](Float px, Float py, Float pz) { return scene.Extinction(px, py, pz); };
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
int FloatLanes() { return (int)hn::Lanes(DF()); }

}  // namespace HWY_NAMESPACE
}  // namespace mmrtm
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mmrtm {

HWY_EXPORT(PlainExtinctionLanes);
HWY_EXPORT(TargetNameLanes);
HWY_EXPORT(FloatLanes);

void PlainExtinctionSimd(const Classifier& classifier, const float* x, const float* y, const float* z, size_t count,
                         float* sigma_t) {
  MMRTM_DCHECK(classifier.plain);
  const VolumeView& v = classifier.proxies[0];
  const int64_t bytes = (int64_t)v.nx * v.ny * v.nz * VoxelTypeSize(v.type);
  // The gathers take 32-bit byte offsets, and a narrow voxel's word is 4
  // bytes of the buffer.
  if (bytes < 4 || bytes >= ((int64_t)1 << 31)) return PlainExtinctionScalar(classifier, x, y, z, count, sigma_t);
  HWY_DYNAMIC_DISPATCH(PlainExtinctionLanes)(classifier, x, y, z, count, sigma_t);
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
int PlainExtinctionLaneCount() { return HWY_DYNAMIC_DISPATCH(FloatLanes)(); }

}  // namespace mmrtm
#endif  // HWY_ONCE
