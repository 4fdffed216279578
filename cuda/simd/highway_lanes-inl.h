// The SIMD lane type: Highway vectors of floats, for the per-lane templates of
// cuda/include/mmrtm (the interface is in mmrtm/scalar_lanes.h). Included
// once per Highway target, inside HWY_NAMESPACE (foreach_target.h), hence
// the toggled guard instead of #pragma once.
//
// The per-lane templates that use this type are defined outside the
// per-target code and so are compiled for the baseline instruction set:
// they may make no always-inline call of a wider target (Highway's own
// operations are always-inline), hence the members and operators here are
// plain `inline`. The templates are MMRTM_INLINE and each target's entry
// point is HWY_FLATTEN, so that all of it is inlined into the target's
// code (with GCC; clang 14 leaves some of a target's own functions out of
// line, which are compiled for that target all the same).
#if defined(MMRTM_SIMD_HIGHWAY_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef MMRTM_SIMD_HIGHWAY_LANES_INL_H_
#undef MMRTM_SIMD_HIGHWAY_LANES_INL_H_
#else
#define MMRTM_SIMD_HIGHWAY_LANES_INL_H_
#endif

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace mmrtm {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A Highway vector wrapped so that the shared templates' operators (+ - *
// /) resolve to the inline operators below, not to Highway's own, which
// are always-inline.
template <class D>
struct LaneVector {
  hn::Vec<D> raw;
};
template <class D>
inline LaneVector<D> operator+(LaneVector<D> a, LaneVector<D> b) {
  return {a.raw + b.raw};
}
template <class D>
inline LaneVector<D> operator-(LaneVector<D> a, LaneVector<D> b) {
  return {a.raw - b.raw};
}
template <class D>
inline LaneVector<D> operator*(LaneVector<D> a, LaneVector<D> b) {
  return {a.raw * b.raw};
}
template <class D>
inline LaneVector<D> operator/(LaneVector<D> a, LaneVector<D> b) {
  return {a.raw / b.raw};
}

// Float lanes of the tag DF, with int32 lanes of the same count.
template <class DF>
struct HighwayLanes {
  using DI = hn::RebindToSigned<DF>;
  using Float = LaneVector<DF>;
  using Int = LaneVector<DI>;
  using Mask = hn::Mask<DF>;

  static inline Float Splat(float v) { return {hn::Set(DF(), v)}; }
  static inline Int SplatInt(int v) { return {hn::Set(DI(), v)}; }
  // x86's min and max instructions are a < b ? a : b and a > b ? a : b,
  // as mmrtm::Min and Max (the NaN of a clamp becomes the bound); other
  // targets' may return NaN, so they select.
#if HWY_ARCH_X86 && HWY_TARGET != HWY_SCALAR && HWY_TARGET != HWY_EMU128
  static inline Float Min(Float a, Float b) { return {hn::Min(a.raw, b.raw)}; }
  static inline Float Max(Float a, Float b) { return {hn::Max(a.raw, b.raw)}; }
#else
  static inline Float Min(Float a, Float b) { return {hn::IfThenElse(a.raw < b.raw, a.raw, b.raw)}; }
  static inline Float Max(Float a, Float b) { return {hn::IfThenElse(a.raw > b.raw, a.raw, b.raw)}; }
#endif
  static inline Int Truncate(Float v) { return {hn::ConvertTo(DI(), v.raw)}; }
  static inline Float ToFloat(Int v) { return {hn::ConvertTo(DF(), v.raw)}; }
  static inline Int MinInt(Int a, Int b) { return {hn::Min(a.raw, b.raw)}; }
  static inline Int Midpoint(Int a, Int b) { return {hn::ShiftRight<1>(a.raw + b.raw)}; }
  static inline Float Select(Mask m, Float yes, Float no) { return {hn::IfThenElse(m, yes.raw, no.raw)}; }
  static inline Int SelectInt(Mask m, Int yes, Int no) {
    return {hn::IfThenElse(hn::RebindMask(DI(), m), yes.raw, no.raw)};
  }
  static inline Mask Less(Float a, Float b) { return a.raw < b.raw; }
  static inline Mask LessEq(Float a, Float b) { return a.raw <= b.raw; }
  static inline Mask Greater(Float a, Float b) { return a.raw > b.raw; }
  static inline Mask GreaterEq(Float a, Float b) { return a.raw >= b.raw; }
  static inline Mask GreaterInt(Int a, Int b) { return hn::RebindMask(DF(), a.raw > b.raw); }
  static inline Mask And(Mask a, Mask b) { return hn::And(a, b); }
  static inline Mask Not(Mask a) { return hn::Not(a); }
  static inline bool AnyTrue(Mask m) { return !hn::AllFalse(DF(), m); }
  static inline bool AllTrue(Mask m) { return hn::AllTrue(DF(), m); }
  static inline Float Gather(const float* base, Int index) { return {hn::GatherIndex(DF(), base, index.raw)}; }
};

}  // namespace HWY_NAMESPACE
}  // namespace mmrtm
HWY_AFTER_NAMESPACE();

#endif  // MMRTM_SIMD_HIGHWAY_LANES_INL_H_
