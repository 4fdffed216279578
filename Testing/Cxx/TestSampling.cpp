// The phase function and the environment light: sampling that matches the
// pdf (chi-square test over a grid of equal-area bins on the sphere). The
// BSDF's tests, and HG's mean cosine, are in TestBSDF.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "environment_map.h"
#include "mmrtm/lights.h"
#include "mmrtm/phase.h"
#include "mmrtm/rng.h"

namespace mmrtm {
namespace {

// Regularised upper incomplete gamma Q(a, x) (Numerical Recipes 6.2).
double GammaQ(double a, double x) {
  if (x <= 0) return 1.0;
  const double gln = std::lgamma(a);
  if (x < a + 1) {
    double sum = 1.0 / a, del = sum, ap = a;
    for (int n = 0; n < 1000; ++n) {
      del *= x / ++ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-14) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::fabs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::fabs(del - 1) < 1e-14) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

Vec3 BinDirection(double cosTheta, double phi) {
  double s = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
  return {(float)(s * std::cos(phi)), (float)(s * std::sin(phi)), (float)cosTheta};
}

struct ChiSquareResult {
  double pValue = 0;
  double pdfIntegral = 0;  // integral of the pdf over the sphere
  int validSamples = 0;
};

// Draws n samples (sample() returns false for "no sample"), bins them on a
// grid uniform in cos(theta) and phi, compares with the pdf integrated over
// each bin (sub x sub midpoint rule), pooling bins expecting fewer than 5.
ChiSquareResult ChiSquare(const std::function<bool(PCG32&, Vec3*)>& sample, const std::function<double(Vec3)>& pdf,
                          int n, int thetaBins = 20, int phiBins = 40, int sub = 8) {
  const int bins = thetaBins * phiBins;
  std::vector<double> observed(bins, 0), expected(bins, 0);
  PCG32 rng(7, 11);
  ChiSquareResult r;
  for (int i = 0; i < n; ++i) {
    Vec3 w;
    if (!sample(rng, &w)) continue;
    ++r.validSamples;
    double phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi;
    int t = std::min(thetaBins - 1, (int)((1 - std::clamp((double)w.z, -1.0, 1.0)) * 0.5 * thetaBins));
    int p = std::min(phiBins - 1, (int)(phi / (2 * kPi) * phiBins));
    observed[t * phiBins + p] += 1;
  }
  const double binArea = 4 * kPi / bins;
  for (int t = 0; t < thetaBins; ++t)
    for (int p = 0; p < phiBins; ++p) {
      double sum = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          double cosTheta = 1 - 2.0 * (t + (a + 0.5) / sub) / thetaBins;
          double phi = 2 * kPi * (p + (b + 0.5) / sub) / phiBins;
          sum += pdf(BinDirection(cosTheta, phi));
        }
      expected[t * phiBins + p] = sum / (sub * sub) * binArea;
      r.pdfIntegral += expected[t * phiBins + p];
    }
  double chi2 = 0, pooledO = 0, pooledE = 0;
  int dof = -1;
  for (int i = 0; i < bins; ++i) {
    double e = expected[i] * n;
    if (e < 5) {
      pooledO += observed[i];
      pooledE += e;
      continue;
    }
    chi2 += (observed[i] - e) * (observed[i] - e) / e;
    ++dof;
  }
  if (pooledE >= 5) {
    chi2 += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
    ++dof;
  } else if (pooledO > 10) {
    chi2 = 1e30;  // samples where the pdf says there are none
  }
  r.pValue = GammaQ(0.5 * std::max(dof, 1), 0.5 * chi2);
  return r;
}

// Significance level of each chi-square test: a test makes at most four, so
// a sampler that matches its pdf fails a test with probability below 1e-4
// (the seeds are fixed, so a run repeats; the level is what a change of the
// random numbers risks). Power: the pdf integrals are held to 1e-2 or
// tighter, so a pdf 5 % off (the planted environment_pdf) fails them.
constexpr double kAlpha = 2.5e-5;

TEST(Phase, HenyeyGreensteinIntegratesToOneAndSamplesItsPdf) {
  const Vec3 wo = Normalize(Vec3{0.3f, -0.2f, 0.9f});
  for (float g : {-0.7f, 0.f, 0.3f, 0.8f}) {
    HGPhaseFunction phase{g};
    ChiSquareResult r = ChiSquare(
        [&](PCG32& rng, Vec3* w) {
          float u0 = rng.Uniform(), u1 = rng.Uniform();
          PhaseSample s = phase.Sample(wo, u0, u1);
          EXPECT_NEAR(s.p, phase.p(wo, s.wi), 1e-3f * s.p);
          *w = s.wi;
          return true;
        },
        [&](Vec3 w) { return phase.Pdf(wo, w); }, 400000);
    EXPECT_NEAR(r.pdfIntegral, 1.0, g > 0.5f ? 1e-2 : 2e-3) << "g " << g;
    EXPECT_GT(r.pValue, kAlpha) << "g " << g;
  }
}

TEST(EnvironmentLight, SamplingMatchesPdf) {
  // A sky with a small bright spot: the pdf must follow it.
  const int w = 64, h = 32;
  std::vector<RGB> texels((size_t)w * h, RGB(0.2f, 0.3f, 0.5f));
  for (int y = 8; y < 11; ++y)
    for (int x = 40; x < 44; ++x) texels[(size_t)y * w + x] = RGB(50.f, 40.f, 30.f);
  for (auto env : {std::make_shared<EnvironmentMap>(w, h, texels), EnvironmentMap::DefaultSky(1.f)}) {
    EnvironmentView view = env->View();
    Light light;
    light.type = LightType::Environment;
    // A sample's pdf and radiance are its texel's; the direction converted
    // back to (u, v) lands in that texel but where float rounding crosses a
    // texel edge (about 1 sample in 10^4 here): a sample whose pdf and
    // radiance are not the direction's counts as a mismatch.
    int samples = 0, mismatches = 0;
    ChiSquareResult r = ChiSquare(
        [&](PCG32& rng, Vec3* dir) {
          float u0 = rng.Uniform(), u1 = rng.Uniform();
          LightSample s = SampleLight(light, view, Vec3{}, u0, u1);
          *dir = s.wi;
          if (s.pdf > 0) {
            ++samples;
            const RGB Le = view.Le(s.wi);
            if (!(std::abs(s.pdf - view.Pdf(s.wi)) <= 1e-3f * s.pdf) || Le.r != s.L.r || Le.g != s.L.g || Le.b != s.L.b)
              ++mismatches;
          }
          return s.pdf > 0.f;
        },
        // Texel edges do not line up with the bins: a finer midpoint rule.
        [&](Vec3 d) { return view.Pdf(d); }, 400000, 32, 64, 32);
    EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-2);
    EXPECT_GT(r.pValue, kAlpha);
    EXPECT_GT(samples, 390000);
    EXPECT_LT(mismatches, samples / 2000) << mismatches << " of " << samples;
  }
}

}  // namespace
}  // namespace mmrtm
