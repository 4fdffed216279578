// Display transform: exposure, a filmic curve, and the sRGB transfer
// function. Per pixel, so that a backend can tone map where the film lives.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

enum class ToneMapper : uint8_t {
  Clamp,   // linear, clipped at 1, sRGB-encoded
  Filmic,  // ACES fit of Narkowicz (2015): soft highlights, sRGB-encoded (the default)
  Off      // the value itself, clipped at 1: as VTK's mappers write colours
           // (their colour functions hold display values, not linear ones)
};

MMRTM_CPU_GPU inline float LinearToSRGB(float v) {
  v = Clamp(v, 0.f, 1.f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.f / 2.4f) - 0.055f;
}

// The inverse of LinearToSRGB on [0, 1].
MMRTM_CPU_GPU inline float SRGBToLinear(float v) {
  v = Clamp(v, 0.f, 1.f);
  return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

MMRTM_CPU_GPU inline float FilmicCurve(float x) {
  const float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
  return Clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.f, 1.f);
}

// Linear radiance to 8-bit sRGB.
MMRTM_CPU_GPU inline void ToneMapPixel(RGB L, float exposure, ToneMapper op, uint8_t out[3]) {
  for (int c = 0; c < 3; ++c) {
    float v = L[c] * exposure;
    if (!(v >= 0.f)) v = 0.f;  // NaN and negatives to black
    if (op == ToneMapper::Filmic) v = FilmicCurve(v);
    out[c] = (uint8_t)((op == ToneMapper::Off ? Clamp(v, 0.f, 1.f) : LinearToSRGB(v)) * 255.f + 0.5f);
  }
}

}  // namespace mmrtm
