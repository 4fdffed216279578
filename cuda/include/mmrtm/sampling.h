// Sample warps with their pdfs, and piecewise-constant distributions (pbrt-v4
// chapter A.1), as views over host-built arrays.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

MMRTM_CPU_GPU inline Vec3 SampleUniformSphere(float u0, float u1) {
  float z = 1.f - 2.f * u0;
  float r = SafeSqrt(1.f - z * z);
  float phi = 2.f * kPi * u1;
  return {r * cosf(phi), r * sinf(phi), z};
}

// Concentric mapping of the unit square to the unit disk (Shirley-Chiu).
MMRTM_CPU_GPU inline void SampleUniformDiskConcentric(float u0, float u1, float* dx, float* dy) {
  float ox = 2.f * u0 - 1.f, oy = 2.f * u1 - 1.f;
  if (ox == 0.f && oy == 0.f) {
    *dx = *dy = 0.f;
    return;
  }
  float r, theta;
  if (fabsf(ox) > fabsf(oy)) {
    r = ox;
    theta = 0.25f * kPi * (oy / ox);
  } else {
    r = oy;
    theta = 0.5f * kPi - 0.25f * kPi * (ox / oy);
  }
  *dx = r * cosf(theta);
  *dy = r * sinf(theta);
}

// Cosine-weighted hemisphere around +z.
MMRTM_CPU_GPU inline Vec3 SampleCosineHemisphere(float u0, float u1) {
  float x, y;
  SampleUniformDiskConcentric(u0, u1, &x, &y);
  return {x, y, SafeSqrt(1.f - x * x - y * y)};
}
MMRTM_CPU_GPU inline float CosineHemispherePdf(float cosTheta) { return cosTheta > 0.f ? cosTheta * kInvPi : 0.f; }

// Piecewise-constant 1D distribution on [0, 1): n function values, n+1 CDF
// entries (cdf[0] = 0, cdf[n] = 1), and the integral of the function.
struct Distribution1DView {
  const float* func = nullptr;
  const float* cdf = nullptr;
  int n = 0;
  float funcIntegral = 0.f;

  // Returns x in [0, 1) with its pdf and the bucket index.
  MMRTM_CPU_GPU float Sample(float u, float* pdf, int* offset) const {
    int lo = 0, hi = n;  // largest lo with cdf[lo] <= u
    while (hi - lo > 1) {
      int mid = (lo + hi) >> 1;
      if (cdf[mid] <= u)
        lo = mid;
      else
        hi = mid;
    }
    *offset = lo;
    float du = u - cdf[lo];
    float width = cdf[lo + 1] - cdf[lo];
    if (width > 0.f) du /= width;
    *pdf = funcIntegral > 0.f ? func[lo] / funcIntegral : 0.f;
    float x = (lo + du) / n;
    return x < kOneMinusEpsilon ? x : kOneMinusEpsilon;
  }
  MMRTM_CPU_GPU float Pdf(float x) const {
    int i = ClampInt((int)(x * n), 0, n - 1);
    return funcIntegral > 0.f ? func[i] / funcIntegral : 0.f;
  }
};

// Piecewise-constant 2D distribution over [0,1)^2: one conditional
// distribution per row (v) and a marginal over rows.
struct Distribution2DView {
  const Distribution1DView* conditional = nullptr;  // nv rows, each over u
  Distribution1DView marginal;                      // over v
  int nu = 0, nv = 0;

  // (u, v) with its pdf; `col` and `row`, when given, the bucket it fell in.
  MMRTM_CPU_GPU void Sample(float u0, float u1, float* u, float* v, float* pdf, int* col = nullptr,
                            int* row = nullptr) const {
    float pdfV, pdfU;
    int r, c;
    *v = marginal.Sample(u1, &pdfV, &r);
    *u = conditional[r].Sample(u0, &pdfU, &c);
    *pdf = pdfU * pdfV;
    if (col) *col = c;
    if (row) *row = r;
  }
  MMRTM_CPU_GPU float Pdf(float u, float v) const {
    int iu = ClampInt((int)(u * nu), 0, nu - 1), iv = ClampInt((int)(v * nv), 0, nv - 1);
    return marginal.funcIntegral > 0.f ? conditional[iv].func[iu] / marginal.funcIntegral : 0.f;
  }
};

// Veach's power heuristic (beta = 2) for two sampling strategies.
MMRTM_CPU_GPU inline float PowerHeuristic(float pdfA, float pdfB) {
  float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0.f ? a / (a + b) : 0.f;
}

}  // namespace mmrtm
