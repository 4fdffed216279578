// Progressive film: per-pixel running mean and variance (Welford) of the
// RGB radiance estimates and the mean alpha, in float, and the running mean
// luminance of the pixel's even samples (replicate 0 of mmrtm/sobol.h).
// The variance is the samples' spread: the standard error of a pixel's mean
// is sqrt(M2 / (n (n - 1))) for independent samples, an overstatement for
// stratified ones. The even samples' mean against the odd ones' gives the
// error of the mean for either kind (Film::Noise).
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

struct FilmView {
  int width = 0, height = 0;
  float* mean = nullptr;           // 4 floats a pixel: RGB radiance and alpha (coverage)
  float* m2 = nullptr;             // 3 floats a pixel: sum of squared deviations of RGB
  float* work = nullptr;           // optional, 1 float a pixel: TraceCounters::Work of its samples
  float* evenLuminance = nullptr;  // required, 1 float a pixel: mean luminance of samples 0, 2, 4 ...
  // Optional, kDenoiserInputFloats a pixel: what the denoised display reads
  // (Film::TrackDenoiserInputs). Running means of the even samples' RGB,
  // of the first-hit albedo and normal guides, and of the even samples'
  // guides, at the offsets below; the odd samples' follow from the whole.
  float* denoiserInputs = nullptr;
  static constexpr int kEvenRGB = 0, kAlbedo = 3, kNormal = 6, kEvenAlbedo = 9, kEvenNormal = 12;
  static constexpr int kDenoiserInputFloats = 15;

  // Adds sample number n (1-based, so sample index n - 1) of pixel (x, y).
  MMRTM_CPU_GPU void AddSample(int x, int y, RGB L, float alpha, uint32_t n) const {
    int64_t i = x + (int64_t)width * y;
    float* m = mean + 4 * i;
    float* s = m2 + 3 * i;
    float inv = 1.f / (float)n;
    for (int c = 0; c < 3; ++c) {
      float delta = L[c] - m[c];
      m[c] += delta * inv;
      s[c] += delta * (L[c] - m[c]);
    }
    m[3] += (alpha - m[3]) * inv;
    if (n & 1u) {  // an even sample index: the (n + 1) / 2-th sample of replicate 0
      float& e = evenLuminance[i];
      e += (Luminance(L) - e) / (float)((n + 1) / 2);
    }
  }
  // The denoiser's inputs of sample number n (as AddSample's), when kept.
  MMRTM_CPU_GPU void AddDenoiserInputs(int x, int y, RGB L, RGB albedo, Vec3 normal, uint32_t n) const {
    if (!denoiserInputs) return;
    float* d = denoiserInputs + kDenoiserInputFloats * (x + (int64_t)width * y);
    const float g[6] = {albedo.r, albedo.g, albedo.b, normal.x, normal.y, normal.z};
    const float inv = 1.f / (float)n;
    for (int c = 0; c < 6; ++c) d[kAlbedo + c] += (g[c] - d[kAlbedo + c]) * inv;
    if (n & 1u) {
      const float invEven = 1.f / (float)((n + 1) / 2);
      for (int c = 0; c < 3; ++c) d[kEvenRGB + c] += (L[c] - d[kEvenRGB + c]) * invEven;
      for (int c = 0; c < 6; ++c) d[kEvenAlbedo + c] += (g[c] - d[kEvenAlbedo + c]) * invEven;
    }
  }
  MMRTM_CPU_GPU void AddWork(int x, int y, float units) const {
    if (work) work[x + (int64_t)width * y] += units;
  }
};

}  // namespace mmrtm
