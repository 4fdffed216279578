// Progressive film: per-pixel running mean and variance (Welford) of the
// RGB radiance estimates and the mean alpha, in float. The variance lets the
// renderer report its own noise: the standard error of a pixel's mean is
// sqrt(M2 / (n (n - 1))).
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

struct FilmView {
  int width = 0, height = 0;
  float* mean = nullptr;  // 4 floats a pixel: RGB radiance and alpha (coverage)
  float* m2 = nullptr;    // 3 floats a pixel: sum of squared deviations of RGB
  float* work = nullptr;  // optional, 1 float a pixel: TraceCounters::Work of its samples

  // Adds sample number n (1-based) of pixel (x, y).
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
  }
  MMRTM_CPU_GPU void AddWork(int x, int y, float units) const {
    if (work) work[x + (int64_t)width * y] += units;
  }
};

}  // namespace mmrtm
