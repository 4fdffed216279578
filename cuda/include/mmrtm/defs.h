// Host/device marking and a few constants shared by every per-sample header.
//
// Everything that runs per sample is marked MMRTM_CPU_GPU (pbrt-v4's
// PBRT_CPU_GPU): __host__ __device__ under nvcc, nothing for a host compiler.
// Code without the macro is host-only set-up. Per-sample code uses no
// exceptions, virtual calls, heap allocation or standard containers
// (DESIGN.md rule 1).
#pragma once

#include <cstdint>
#include <math.h>

#if defined(__CUDACC__)
#define MMRTM_CPU_GPU __host__ __device__
#else
#define MMRTM_CPU_GPU
#endif

// For the few per-sample functions that the host compiler leaves out of line
// although they are called at every density lookup (its call and spills cost
// more than their body saves in code size).
#if defined(__CUDACC__)
#define MMRTM_INLINE __forceinline__
#elif defined(__GNUC__)
#define MMRTM_INLINE inline __attribute__((always_inline))
#else
#define MMRTM_INLINE inline
#endif

// Debug-only check; compiled out on the device and in release builds.
#if !defined(NDEBUG) && !defined(__CUDA_ARCH__)
#include <cassert>
#define MMRTM_DCHECK(x) assert(x)
#else
#define MMRTM_DCHECK(x) ((void)0)
#endif

namespace mmrtm {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInv2Pi = 0.15915494309189533577f;
constexpr float kInv4Pi = 0.07957747154594766788f;
constexpr float kInfinity = 3.402823466e38f;  // FLT_MAX: a float "no hit"

// Largest float strictly below one: clamps uniform samples to [0, 1).
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

MMRTM_CPU_GPU inline float Clamp(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
MMRTM_CPU_GPU inline int ClampInt(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }
MMRTM_CPU_GPU inline int MinInt(int a, int b) { return a < b ? a : b; }
// floor(v) clamped to [0, hi] (hi >= 0), and 0 for NaN. The conversion
// truncates only values in [1, hi), where truncation is the floor: one
// instruction where floorf is about ten without SSE4.1, and no value beyond
// int's range reaches it.
MMRTM_CPU_GPU inline int FloorClamped(float v, int hi) { return v >= 1.f ? (v < (float)hi ? (int)v : hi) : 0; }
MMRTM_CPU_GPU inline float Min(float a, float b) { return a < b ? a : b; }
MMRTM_CPU_GPU inline float Max(float a, float b) { return a > b ? a : b; }
MMRTM_CPU_GPU inline float Lerp(float t, float a, float b) { return (1.f - t) * a + t * b; }
MMRTM_CPU_GPU inline float Sqr(float v) { return v * v; }
MMRTM_CPU_GPU inline float SafeSqrt(float v) { return sqrtf(v > 0.f ? v : 0.f); }

}  // namespace mmrtm
