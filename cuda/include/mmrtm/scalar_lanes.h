// The scalar lane type: what per-lane code is instantiated with on the GPU
// and in the scalar CPU path (DESIGN.md: the per-lane math is one source,
// instantiated for a float and for a SIMD vector).
//
// Per-lane code (VolumeView's cell arithmetic, the CCTF's segment search and
// interpolation, the plain scene's extinction) is written as templates over
// a lane type L that provides:
//   Float, Int, Mask             a float, an int and a comparison result per lane
//   Splat(float) / SplatInt(int) the same value in every lane
//   Min, Max                     as mmrtm::Min/Max: a < b ? a : b and a > b ? a : b,
//                                so that Max(NaN, 0) is 0 in every lane type
//   Truncate(Float)              to Int, toward zero (the caller keeps it in int range)
//   ToFloat(Int), MinInt(Int, Int), Midpoint(Int, Int) ((a + b) >> 1)
//   Select(Mask, Float, Float), SelectInt(Mask, Int, Int)
//   Less/LessEq/Greater/GreaterEq(Float, Float), GreaterInt(Int, Int) -> Mask
//   And(Mask, Mask), Not(Mask), AnyTrue(Mask), AllTrue(Mask)
//   Gather(const float* base, Int index)   base[index] per lane
// and arithmetic operators + - * / on Float and + - * on Int.
// A SIMD lane type (cuda/simd, host only: nvcc never sees it) provides the
// same over N lanes; control flow that depends on lane values goes through
// AnyTrue/AllTrue, which for one lane are the plain branch.
// The per-lane templates are MMRTM_INLINE: they are defined outside any
// SIMD target's code, so a SIMD instantiation left out of line would be
// compiled for the baseline instruction set, and would take its vectors
// in memory (cuda/simd/highway_lanes-inl.h).
#pragma once

#include "mmrtm/defs.h"

namespace mmrtm {

struct ScalarLanes {
  using Float = float;
  using Int = int;
  using Mask = bool;

  MMRTM_CPU_GPU static float Splat(float v) { return v; }
  MMRTM_CPU_GPU static int SplatInt(int v) { return v; }
  MMRTM_CPU_GPU static float Min(float a, float b) { return mmrtm::Min(a, b); }
  MMRTM_CPU_GPU static float Max(float a, float b) { return mmrtm::Max(a, b); }
  MMRTM_CPU_GPU static int Truncate(float v) { return (int)v; }
  MMRTM_CPU_GPU static float ToFloat(int v) { return (float)v; }
  MMRTM_CPU_GPU static int MinInt(int a, int b) { return mmrtm::MinInt(a, b); }
  MMRTM_CPU_GPU static int Midpoint(int a, int b) { return (a + b) >> 1; }
  MMRTM_CPU_GPU static float Select(bool m, float yes, float no) { return m ? yes : no; }
  MMRTM_CPU_GPU static int SelectInt(bool m, int yes, int no) { return m ? yes : no; }
  MMRTM_CPU_GPU static bool Less(float a, float b) { return a < b; }
  MMRTM_CPU_GPU static bool LessEq(float a, float b) { return a <= b; }
  MMRTM_CPU_GPU static bool Greater(float a, float b) { return a > b; }
  MMRTM_CPU_GPU static bool GreaterEq(float a, float b) { return a >= b; }
  MMRTM_CPU_GPU static bool GreaterInt(int a, int b) { return a > b; }
  MMRTM_CPU_GPU static bool And(bool a, bool b) { return a && b; }
  MMRTM_CPU_GPU static bool Not(bool a) { return !a; }
  MMRTM_CPU_GPU static bool AnyTrue(bool m) { return m; }
  MMRTM_CPU_GPU static bool AllTrue(bool m) { return m; }
  MMRTM_CPU_GPU static float Gather(const float* base, int index) { return base[index]; }
};

// (1 - t) a + t b, the one interpolation of every lookup and curve (vecmath's
// Lerp is this for ScalarLanes).
template <class L>
MMRTM_INLINE MMRTM_CPU_GPU typename L::Float LerpLanes(typename L::Float t, typename L::Float a, typename L::Float b) {
  return (L::Splat(1.f) - t) * a + t * b;
}

}  // namespace mmrtm
