// Compiled once per Highway target (foreach_target.h re-includes this file),
// with -ffp-contract=off (cuda/CMakeLists.txt), so that every operation
// rounds as the scalar one does. The scalar code mirrored here operation by
// operation: PixelSampleRNG and PCG32::SetSequence (mmrtm/rng.h),
// SobolPairs (mmrtm/sobol.h), CameraSample (mmrtm/integrator.h),
// CameraView::GenerateRay (mmrtm/camera.h), SceneView::DomainInterval
// (mmrtm/scene_view.h) and IntersectBox (mmrtm/ray.h).
#include "camera_path_starts.h"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "simd/camera_path_starts.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "mmrtm/integrator.h"
#include "mmrtm/rng.h"
#include "mmrtm/sobol.h"

HWY_BEFORE_NAMESPACE();
namespace mmrtm {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DU64 = hn::ScalableTag<uint64_t>;
using VU64 = hn::Vec<DU64>;
using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;

// MixBits.
HWY_INLINE VU64 MixBitsLanes(VU64 v) {
  const DU64 d;
  v = hn::Xor(v, hn::ShiftRight<31>(v));
  v = v * hn::Set(d, kMixBitsMultiplier0);
  v = hn::Xor(v, hn::ShiftRight<27>(v));
  v = v * hn::Set(d, kMixBitsMultiplier1);
  return hn::Xor(v, hn::ShiftRight<33>(v));
}

// ReverseBits32 (the CPU's branch).
HWY_INLINE VU ReverseBits32Lanes(VU v) {
  const DU d;
  v = hn::Or(hn::ShiftLeft<16>(v), hn::ShiftRight<16>(v));
  v = hn::Or(hn::ShiftLeft<8>(hn::And(v, hn::Set(d, 0x00ff00ffu))),
             hn::ShiftRight<8>(hn::And(v, hn::Set(d, 0xff00ff00u))));
  v = hn::Or(hn::ShiftLeft<4>(hn::And(v, hn::Set(d, 0x0f0f0f0fu))),
             hn::ShiftRight<4>(hn::And(v, hn::Set(d, 0xf0f0f0f0u))));
  v = hn::Or(hn::ShiftLeft<2>(hn::And(v, hn::Set(d, 0x33333333u))),
             hn::ShiftRight<2>(hn::And(v, hn::Set(d, 0xccccccccu))));
  return hn::Or(hn::ShiftLeft<1>(hn::And(v, hn::Set(d, 0x55555555u))),
                hn::ShiftRight<1>(hn::And(v, hn::Set(d, 0xaaaaaaaau))));
}

// SobolDimension1Reversed.
HWY_INLINE VU SobolDimension1ReversedLanes(VU index) {
  const DU d;
  index = hn::Xor(index, hn::And(hn::ShiftRight<1>(index), hn::Set(d, 0x55555555u)));
  index = hn::Xor(index, hn::And(hn::ShiftRight<2>(index), hn::Set(d, 0x33333333u)));
  index = hn::Xor(index, hn::And(hn::ShiftRight<4>(index), hn::Set(d, 0x0f0f0f0fu)));
  index = hn::Xor(index, hn::And(hn::ShiftRight<8>(index), hn::Set(d, 0x00ff00ffu)));
  return hn::Xor(index, hn::And(hn::ShiftRight<16>(index), hn::Set(d, 0x0000ffffu)));
}

// OwenScrambleReversed.
HWY_INLINE VU OwenScrambleReversedLanes(VU v, VU seed) {
  const DU d;
  v = hn::Xor(v, v * hn::Set(d, kOwenMultiplier0));
  v = v + seed;
  v = v * hn::Or(hn::ShiftRight<16>(seed), hn::Set(d, 1u));
  v = hn::Xor(v, v * hn::Set(d, kOwenMultiplier1));
  v = hn::Xor(v, v * hn::Set(d, kOwenMultiplier2));
  return ReverseBits32Lanes(v);
}

// UniformFloat.
HWY_INLINE VF UniformFloatLanes(VU bits) {
  const DF df;
  const VF u = hn::ConvertTo(df, hn::BitCast(DI(), hn::ShiftRight<8>(bits))) * hn::Set(df, 0x1p-24f);
  return hn::IfThenElse(u < hn::Set(df, kOneMinusEpsilon), u, hn::Set(df, kOneMinusEpsilon));
}

// Dot(a, b) and the affine maps, in the scalar order of their terms.
HWY_INLINE VF DotLanes(const VF a[3], const VF b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
HWY_INLINE VF MinF(VF a, VF b) { return hn::IfThenElse(a < b, a, b); }
HWY_INLINE VF MaxF(VF a, VF b) { return hn::IfThenElse(a > b, a, b); }

// SobolPairs::Get's two hashes of pair `pair`, for the pass in 32-bit lanes:
// the index's scramble seed and the two coordinates'.
struct PairWords {
  uint32_t* index;
  uint32_t* u0;
  uint32_t* u1;
};

// The 64-bit half: each sample's PCG32 stream and Sobol' key, and the
// hashes of its pairs.
void StartNumbers(const SceneView& s, CameraPathStarts& st, const PairWords words[2], const int pairs[2]) {
  const DU64 d;
  const hn::Rebind<uint32_t, DU64> d32;
  const size_t n = hn::Lanes(d);
  const uint64_t seed = (uint64_t)s.settings.seed;
  const VU64 sequenceKey = hn::Set(d, MixBits(seed + kPixelSequenceSalt));
  const VU64 sobolKey[2] = {hn::Set(d, MixBits(seed + kSobolKeySalt + 0u * kSobolReplicateMultiplier)),
                            hn::Set(d, MixBits(seed + kSobolKeySalt + 1u * kSobolReplicateMultiplier))};
  const VU64 width = hn::Set(d, (uint64_t)s.camera.width), one = hn::Set(d, 1);
  for (size_t i = 0; i < st.Size(); i += n) {
    const VU64 x = hn::PromoteTo(d, hn::LoadU(d32, reinterpret_cast<const uint32_t*>(st.x.data()) + i));
    const VU64 y = hn::PromoteTo(d, hn::LoadU(d32, reinterpret_cast<const uint32_t*>(st.y.data()) + i));
    const VU64 index = hn::PromoteTo(d, hn::LoadU(d32, st.sampleIndex.data() + i));
    const VU64 pixel = x + width * y;
    // PixelSampleRNG, and SetSequence's two steps from state 0.
    const VU64 sequence = MixBitsLanes(hn::Xor(pixel, sequenceKey));
    const VU64 offset = MixBitsLanes(index * hn::Set(d, kSampleOffsetMultiplier) + hn::Set(d, seed));
    const VU64 inc = hn::Or(hn::ShiftLeft<1>(sequence), one);
    const VU64 state = (inc + offset) * hn::Set(d, kPCG32Multiplier) + inc;
    hn::StoreU(state, d, st.rngState.data() + i);
    hn::StoreU(inc, d, st.rngInc.data() + i);
    // SobolPairs' key, by the sample's replicate.
    const auto odd = hn::And(index, one) == one;
    const VU64 key = MixBitsLanes(hn::Xor(pixel, hn::IfThenElse(odd, sobolKey[1], sobolKey[0])));
    hn::StoreU(key, d, st.sobolKey.data() + i);
    for (int p = 0; p < 2; ++p) {
      const VU64 h = MixBitsLanes(key + hn::Set(d, (uint64_t)(pairs[p] + 1) * kSobolPairMultiplier));
      hn::StoreU(hn::TruncateTo(d32, MixBitsLanes(h)), d32, words[p].index + i);
      hn::StoreU(hn::TruncateTo(d32, h), d32, words[p].u0 + i);
      hn::StoreU(hn::TruncateTo(d32, hn::ShiftRight<32>(h)), d32, words[p].u1 + i);
    }
  }
}

void StartCameraPathsLanes(const SceneView& s, CameraPathStarts& st) {
  uint32_t* scratch = st.pairHashes.data();
  const size_t stride = st.pairHashes.size() / 6;
  const DF df;
  const DI di;
  const DU du;
  const size_t n = hn::Lanes(df);
  const int pairs[2] = {kPairPixel, kPairFirstVertex + kPairFreePath};
  const PairWords words[2] = {{scratch, scratch + stride, scratch + 2 * stride},
                              {scratch + 3 * stride, scratch + 4 * stride, scratch + 5 * stride}};
  StartNumbers(s, st, words, pairs);

  const CameraView& cam = s.camera;
  const float aspect = (float)cam.width / (float)cam.height;
  const VF width = hn::Set(df, (float)cam.width), height = hn::Set(df, (float)cam.height);
  const VF two = hn::Set(df, 2.f), oneF = hn::Set(df, 1.f), zeroF = hn::Zero(df);
  const VF inf = hn::Set(df, kInfinity);
  const bool ortho = cam.projection == Projection::Orthographic;
  const float extent = ortho ? cam.orthoHalfHeight : cam.tanHalfFovY;
  const Affine3& w2i = s.classifier.proxies[0].worldToIndex;
  for (size_t i = 0; i < st.Size(); i += n) {
    // SobolPairs::Get of the pixel's pair and the free path's.
    const VU reversed = ReverseBits32Lanes(hn::ShiftRight<1>(hn::LoadU(du, st.sampleIndex.data() + i)));
    hn::StoreU(reversed, du, st.sobolReversedIndex.data() + i);
    VF u[2][2];
    for (int p = 0; p < 2; ++p) {
      const VU index = OwenScrambleReversedLanes(reversed, hn::LoadU(du, words[p].index + i));
      u[p][0] = UniformFloatLanes(OwenScrambleReversedLanes(index, hn::LoadU(du, words[p].u0 + i)));
      u[p][1] = UniformFloatLanes(
          OwenScrambleReversedLanes(SobolDimension1ReversedLanes(index), hn::LoadU(du, words[p].u1 + i)));
    }
    hn::StoreU(u[1][0], df, st.freePathU0.data() + i);
    hn::StoreU(u[1][1], df, st.freePathU1.data() + i);

    // GenerateRay(x + fx, y + fy), a pinhole.
    const VI x = hn::LoadU(di, st.x.data() + i), y = hn::LoadU(di, st.y.data() + i);
    const VF px = hn::ConvertTo(df, x) + u[0][0], py = hn::ConvertTo(df, y) + u[0][1];
    const VF sx = (two * px / width - oneF + hn::Set(df, cam.windowCenterX)) * hn::Set(df, aspect);
    const VF sy = oneF - two * py / height + hn::Set(df, cam.windowCenterY);
    const VF a = sx * hn::Set(df, extent), b = sy * hn::Set(df, extent);
    VF o[3], d[3];
    for (int k = 0; k < 3; ++k) {
      if (ortho) {
        o[k] = hn::Set(df, cam.position[k]) + hn::Set(df, cam.right[k]) * a + hn::Set(df, cam.up[k]) * b;
        d[k] = hn::Set(df, cam.forward[k]);
      } else {
        o[k] = hn::Set(df, cam.position[k]);
        d[k] = hn::Set(df, cam.forward[k]) + hn::Set(df, cam.right[k]) * a + hn::Set(df, cam.up[k]) * b;
      }
    }
    if (!ortho) {  // Normalize: v / Length(v), a reciprocal and three products
      const VF r = oneF / hn::Sqrt(DotLanes(d, d));
      for (int k = 0; k < 3; ++k) d[k] = d[k] * r;
    }
    VF tMax = inf;
    if (s.cameraRayMaxDistance) tMax = hn::GatherIndex(df, s.cameraRayMaxDistance, x + hn::Set(di, cam.width) * y);
    for (int k = 0; k < 3; ++k) {
      hn::StoreU(o[k], df, st.o[k].data() + i);
      hn::StoreU(d[k], df, st.d[k].data() + i);
    }
    hn::StoreU(tMax, df, st.tMax.data() + i);

    // DomainInterval: the index ray, the box [0, n - 1], the clip planes.
    VF io[3], id[3];
    for (int r = 0; r < 3; ++r) {
      io[r] = hn::Set(df, w2i.m[r][0]) * o[0] + hn::Set(df, w2i.m[r][1]) * o[1] + hn::Set(df, w2i.m[r][2]) * o[2] +
              hn::Set(df, w2i.m[r][3]);
      id[r] = hn::Set(df, w2i.m[r][0]) * d[0] + hn::Set(df, w2i.m[r][1]) * d[1] + hn::Set(df, w2i.m[r][2]) * d[2];
      hn::StoreU(io[r], df, st.indexO[r].data() + i);
      hn::StoreU(id[r], df, st.indexD[r].data() + i);
    }
    VF t0 = zeroF, t1 = tMax;
    MF hit = hn::Not(hn::FirstN(df, 0));
    for (int k = 0; k < 3; ++k) {
      const VF inv = oneF / id[k];
      VF tNear = (zeroF - io[k]) * inv, tFar = (hn::Set(df, (float)(s.domain[k] - 1)) - io[k]) * inv;
      const MF swap = tNear > tFar;
      const VF near = hn::IfThenElse(swap, tFar, tNear);
      tFar = hn::IfThenElse(swap, tNear, tFar);
      tNear = near;
      tFar = tFar * hn::Set(df, 1.f + 2.f * 3.f * 0x1p-24f);
      // Once a slab misses, the scalar test returns; later slabs' values
      // do not matter.
      t0 = hn::IfThenElse(tNear > t0, tNear, t0);
      t1 = hn::IfThenElse(tFar < t1, tFar, t1);
      hit = hn::AndNot(t0 > t1, hit);
    }
    for (int c = 0; c < s.clipPlaneCount; ++c) {
      const ClipPlane& plane = s.clipPlanes[c];
      const VF normal[3] = {hn::Set(df, plane.normal.x), hn::Set(df, plane.normal.y), hn::Set(df, plane.normal.z)};
      const VF along = DotLanes(normal, d);
      const VF at0 = DotLanes(normal, o) + hn::Set(df, plane.offset);
      const MF parallel = along == zeroF;
      hit = hn::AndNot(hn::And(parallel, at0 < zeroF), hit);
      const VF t = hn::Neg(at0) / along;
      const MF entering = hn::AndNot(parallel, along > zeroF);
      const MF leaving = hn::Not(hn::Or(parallel, along > zeroF));  // along < 0, or NaN
      t0 = hn::IfThenElse(entering, MaxF(t0, t), t0);
      t1 = hn::IfThenElse(leaving, MinF(t1, t), t1);
    }
    hit = hn::And(hit, t0 < t1);
    hn::StoreU(t0, df, st.t0.data() + i);
    hn::StoreU(t1, df, st.t1.data() + i);
    hn::StoreU(hn::IfThenElseZero(hn::RebindMask(di, hit), hn::Set(di, 1)), di, st.inDomain.data() + i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace mmrtm
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace mmrtm {

HWY_EXPORT(StartCameraPathsLanes);

namespace {
// Whole vectors past the last sample: the widest vector of any target
// (SVE's 2048 bits; HWY_MAX_BYTES here is the last target's).
constexpr size_t kPad = 256 / sizeof(float);
}  // namespace

void CameraPathStarts::Resize(size_t n) {
  size_ = n;
  const size_t padded = n + kPad;
  // The padding's inputs are zeros or earlier samples: valid pixels, whose
  // starts are computed and dropped.
  for (auto* v : {&x, &y}) v->resize(padded);
  sampleIndex.resize(padded);
  for (auto* v : {&rngState, &rngInc, &sobolKey}) v->resize(padded);
  sobolReversedIndex.resize(padded);
  for (int a = 0; a < 3; ++a)
    for (auto* v : {&o[a], &d[a], &indexO[a], &indexD[a]}) v->resize(padded);
  for (auto* v : {&tMax, &freePathU0, &freePathU1, &t0, &t1}) v->resize(padded);
  inDomain.resize(padded);
  pairHashes.resize(6 * padded);
}

bool CameraPathStartsRun(const SceneView& s) {
  return s.settings.sampler == PixelSampler::Sobol && !(s.camera.lensRadius > 0.f) &&
         (int64_t)s.camera.width * s.camera.height < ((int64_t)1 << 31);
}

void StartCameraPaths(const SceneView& s, CameraPathStarts& starts) {
  MMRTM_DCHECK(CameraPathStartsRun(s));
  HWY_DYNAMIC_DISPATCH(StartCameraPathsLanes)(s, starts);
}

}  // namespace mmrtm
#endif  // HWY_ONCE
