// The surface BSDF (mmrtm/bsdf.h) and the Henyey-Greenstein phase function
// (mmrtm/phase.h) against formulas written from their sources
// (ReferenceBSDF.h: GGX after Walter 2007 and Heitz 2014/2018, Schlick's
// Fresnel, the diffuse weight bsdf.h documents; HG's mean cosine g), not
// against the code's own functions.
//
// Deterministic checks integrate over directions (ReferenceBSDF.h's
// quadrature), so that their tolerances are the quadrature's error (checked
// on integrals known in closed form) and float rounding, not a statistical
// one. Statistical checks (chi-square of sampling, Monte Carlo albedo, HG's
// sampled mean cosine) have a false-failure probability of 1e-4 per test
// (Bonferroni over its cases), print their power, and assert it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <thread>
#include <vector>

#include "ImageAgreement.h"  // NormalQuantile
#include "ReferenceBSDF.h"
#include "mmrtm/bsdf.h"
#include "mmrtm/phase.h"
#include "mmrtm/rng.h"

namespace mmrtm {
namespace {

using namespace test;

Vec3 ToF(D3 a) { return {(float)a.x, (float)a.y, (float)a.z}; }
D3 FromF(Vec3 a) { return {a.x, a.y, a.z}; }

// False-failure probability of each statistical test, and the probability
// with which a bias of the stated power makes it fail.
constexpr double kFalseFailure = 1e-4;
// The aim: a 3 % change of one lobe fails.
constexpr double kRequiredPower = 0.03;

// The code's BSDF for the same parameters, normal +z.
SurfaceBSDF CodeBSDF(const ReferenceBSDF& r, D3 wo, float roughness) {
  return SurfaceBSDF::Make({0.f, 0.f, 1.f}, ToF(wo), RGB((float)r.base[0], (float)r.base[1], (float)r.base[2]),
                           roughness, (float)r.metallic);
}
Rgb3 ToRgb3(RGB c) { return {c.r, c.g, c.b}; }

// How closely an integral of the code's specular lobe (float) can match the
// reference (double): bsdf.h's D divides by d^2, d = cos^2 (alpha^2 - 1) +
// 1, whose float sum loses its leading bits where d is small (alpha^2 at the
// peak). The relative error of D is a few 1e-7 / d, and the mean of 1 / d
// over the lobe about 1 / (2 alpha^2): 1e-7 / alpha^2 bounds it (measured
// up to 6e-4 at the lowest alpha, 0.01; below 3e-5 from alpha 0.09 up).
double SpecularFloatTolerance(double alpha) { return 2e-5 + 1e-7 / (alpha * alpha); }

// ---------------------------------------------------------------------------
// Statistics.

// The chi-square quantile at upper tail p (Wilson-Hilferty). Conservative:
// the exact tail probability at this limit is 0.99 to 1 times p for the
// 870-1800 degrees of freedom of these tests (0.83-0.95 times at 50), at
// p from 1e-7 to 5e-5.
double ChiSquareQuantile(double dof, double p) {
  const double z = NormalQuantile(1 - p), a = 2 / (9 * dof);
  return dof * std::pow(1 - a + z * std::sqrt(a), 3);
}

// The noncentrality lambda at which a chi-square test with `dof` degrees of
// freedom and limit `limit` fails with probability 1 - kFalseFailure
// (Patnaik: chi'^2(dof, lambda) ~ c chi^2(f), c = (dof + 2 lambda) / (dof +
// lambda), f = (dof + lambda)^2 / (dof + 2 lambda); its lower quantile by
// Wilson-Hilferty).
double NoncentralityForPower(double dof, double limit) {
  double lo = 0, hi = 1e7;
  for (int i = 0; i < 200; ++i) {
    const double lambda = (lo + hi) / 2, c = (dof + 2 * lambda) / (dof + lambda),
                 f = (dof + lambda) * (dof + lambda) / (dof + 2 * lambda);
    (c * ChiSquareQuantile(f, 1 - kFalseFailure) >= limit ? hi : lo) = lambda;
  }
  return hi;
}

// P(Poisson(mean) >= k).
double PoissonUpperTail(double mean, double k) {
  double term = std::exp(-mean), below = 0;
  for (int i = 0; i < k; ++i) {
    below += term;
    term *= mean / (i + 1);
  }
  return std::max(0.0, 1 - below);
}

struct ChiSquareOutcome {
  double statistic = 0, limit = 0;
  int dof = 0;
  // Power: the smallest delta such that a sampler whose density is
  // (1 + delta) p on a half of the probability and (1 - delta) p on the
  // other half (noncentrality n delta^2) fails with probability 1 - 1e-4.
  double power = 0;
  bool sparseCellsAgree = true;  // pooled cells with under 5 expected samples
  bool Passes() const { return statistic <= limit && sparseCellsAgree; }
};

// The chi-square tests draw their samples and integrate their bins on two
// threads (the test's share of the CI's two cores).
constexpr int kThreads = 2;
void OnThreads(const std::function<void(int)>& work) {
  std::thread other(work, 1);
  work(0);
  other.join();
}

// The integral of a density over a rectangle in (theta, phi), in solid
// angle: 4 x 4 Gauss-Legendre nodes.
struct Rect {
  double theta0, theta1, phi0, phi1;
};
double RectMass(const std::function<double(D3)>& pdf, const Rect& r) {
  static const GaussLegendre gl(4);
  double mass = 0;
  PanelNodes({r.theta0, r.theta1}, gl, [&](double theta, double wt) {
    PanelNodes({r.phi0, r.phi1}, gl,
               [&](double phi, double wp) { mass += wt * wp * std::sin(theta) * pdf(Spherical(theta, phi)); });
  });
  return mass;
}
// Splits into quarters while the quarters' sum moves the expected count
// (n times the mass) by more than 0.01 of its Poisson spread.
double AdaptiveMass(const std::function<double(D3)>& pdf, const Rect& r, double whole, int n, int depth) {
  const double tm = (r.theta0 + r.theta1) / 2, pm = (r.phi0 + r.phi1) / 2;
  const Rect q[4] = {
      {r.theta0, tm, r.phi0, pm}, {tm, r.theta1, r.phi0, pm}, {r.theta0, tm, pm, r.phi1}, {tm, r.theta1, pm, r.phi1}};
  double m[4], sum = 0;
  for (int i = 0; i < 4; ++i) sum += m[i] = RectMass(pdf, q[i]);
  if (depth >= 6 || std::fabs(sum - whole) * n <= 0.01 * std::sqrt(std::max(1.0, sum * n))) return sum;
  double refined = 0;
  for (int i = 0; i < 4; ++i) refined += AdaptiveMass(pdf, q[i], m[i], n, depth + 1);
  return refined;
}

// Goodness of fit of a sampler to a density over the upper hemisphere.
// Bins: theta edges thetaOfT(k / thetaBins) (thetaOfT(1) = pi/2), phi
// uniform, and one bin for everything else (below the horizon, or no
// sample: its expectation is 1 minus the density's integral over the
// bins). Expected counts by Gauss-Legendre quadrature of the density. Bins
// expecting under 5 samples are pooled; under H0 the statistic is
// chi-square with (cells - 1) degrees of freedom, and the test fails above
// its 1 - falseFailure / 2 quantile (the other half for a pool too small
// to be a cell, tested on its Poisson tail).
ChiSquareOutcome ChiSquareOnHemisphere(const std::function<bool(PCG32&, D3*)>& sample,
                                       const std::function<double(D3)>& pdf,
                                       const std::function<double(double)>& thetaOfT, int n, double falseFailure,
                                       int thetaBins = 40, int phiBins = 40) {
  std::vector<double> thetaEdges(thetaBins + 1);
  for (int k = 0; k <= thetaBins; ++k) thetaEdges[k] = thetaOfT((double)k / thetaBins);
  const int bins = thetaBins * phiBins;  // + 1: everything else
  std::vector<double> observed(bins + 1, 0), expected(bins + 1, 0);
  std::vector<double> observedByThread[kThreads];
  OnThreads([&](int thread) {
    std::vector<double>& o = observedByThread[thread];
    o.assign(bins + 1, 0);
    PCG32 rng(17 + thread, 5);
    for (int i = thread; i < n; i += kThreads) {
      D3 w;
      if (!sample(rng, &w) || !(w.z > 0)) {
        o[bins] += 1;
        continue;
      }
      const double theta = std::atan2(std::sqrt(w.x * w.x + w.y * w.y), w.z);
      double phi = std::atan2(w.y, w.x);
      if (phi < 0) phi += 2 * kPiD;
      const int t =
          std::clamp((int)(std::upper_bound(thetaEdges.begin(), thetaEdges.end(), theta) - thetaEdges.begin()) - 1, 0,
                     thetaBins - 1);
      const int p = std::min(phiBins - 1, (int)(phi / (2 * kPiD) * phiBins));
      o[t * phiBins + p] += 1;
    }
  });
  for (const std::vector<double>& o : observedByThread)
    for (int i = 0; i <= bins; ++i) observed[i] += o[i];
  // Each bin's theta range in 4 sub-panels equal in t, which follow the
  // density's mass, and those wider than a factor 1.25 in theta split
  // geometrically (GGX's tail at alpha = 0.01 falls as theta^-3 over a last
  // bin from 3.5 to 90 degrees); each piece integrated adaptively
  // (AdaptiveMass) until its expected count is right to 0.01 of its
  // statistical spread, so that quadrature adds under 0.01^2 per bin to
  // the statistic (a GGX lobe reflected at grazing wo is only two or three
  // bins wide in phi).
  const int sub = 4;
  double insideByThread[kThreads] = {};
  OnThreads([&](int thread) {
    std::vector<double> subEdges;
    for (int t = thread; t < thetaBins; t += kThreads) {
      subEdges.clear();
      for (int k = 0; k <= sub; ++k) {
        const double theta = thetaOfT((t + (double)k / sub) / thetaBins);
        if (!subEdges.empty() && subEdges.back() > 0 && theta > 1.25 * subEdges.back()) {
          const double a = subEdges.back();
          const int pieces = (int)std::ceil(std::log(theta / a) / std::log(1.25));
          for (int j = 1; j < pieces; ++j) subEdges.push_back(a * std::pow(theta / a, (double)j / pieces));
        }
        subEdges.push_back(theta);
      }
      for (int p = 0; p < phiBins; ++p) {
        double mass = 0;
        const double dPhi = 2 * kPiD / phiBins;
        for (size_t k = 0; k + 1 < subEdges.size(); ++k) {
          const Rect r{subEdges[k], subEdges[k + 1], p * dPhi, (p + 1) * dPhi};
          mass += AdaptiveMass(pdf, r, RectMass(pdf, r), n, 0);
        }
        expected[t * phiBins + p] = mass * n;
        insideByThread[thread] += mass;
      }
    }
  });
  const double inside = insideByThread[0] + insideByThread[1];
  expected[bins] = std::max(0.0, 1 - inside) * n;

  ChiSquareOutcome r;
  double pooledO = 0, pooledE = 0;
  int cells = 0;
  for (int i = 0; i <= bins; ++i) {
    if (expected[i] < 5) {
      pooledO += observed[i];
      pooledE += expected[i];
      continue;
    }
    r.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++cells;
  }
  if (pooledE >= 5) {
    r.statistic += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
    ++cells;
  } else {
    // Too few for a chi-square cell: a Poisson tail test on what the pooled
    // bins received, with half the budget.
    r.sparseCellsAgree = PoissonUpperTail(pooledE, pooledO) > falseFailure / 2;
  }
  r.dof = cells - 1;
  r.limit = ChiSquareQuantile(r.dof, falseFailure / 2);
  r.power = std::sqrt(NoncentralityForPower(r.dof, r.limit) / n);
  return r;
}

// Mean and standard error of n independent values.
struct MeanEstimate {
  double sum = 0, sum2 = 0;
  int n = 0;
  void Add(double v) {
    sum += v;
    sum2 += v * v;
    ++n;
  }
  double Mean() const { return sum / n; }
  double StandardError() const { return std::sqrt(std::max(0.0, sum2 / n - Mean() * Mean()) / (n - 1)); }
};

// ---------------------------------------------------------------------------
// The reference formulas against the code, point by point.

TEST(GGX, DistributionAndMaskingAreTheReferenceFormulas) {
  for (double roughness : {0.1, 0.3, 0.6, 1.0}) {
    const ReferenceBSDF ref = ReferenceBSDF::Make({1, 1, 1}, roughness, 0);
    const GGX ggx{(float)ref.alpha};
    for (double theta : {0.0, 0.1, 0.5, 1.0, 1.4, 1.55})
      for (double phi : {0.0, 2.0}) {
        const D3 w = Spherical(theta, phi);
        // bsdf.h's D divides by d^2, d = cos^2 (alpha^2 - 1) + 1, whose float
        // sum loses its bits where d is small (alpha^2 at the peak): a
        // relative rounding of up to 2 x 6e-8 / d in D.
        const double d = w.z * w.z * (ref.alpha * ref.alpha - 1) + 1, rounding = 2e-5 + 2.4e-7 / d;
        EXPECT_NEAR(ggx.D(ToF(w)), ref.D(w), rounding * ref.D(w)) << roughness << " " << theta;
        EXPECT_NEAR(ggx.G1(ToF(w)), ref.G1(w), 2e-6) << roughness << " " << theta;
        const D3 wo = OutgoingAt(0.6);
        if (Dot(wo, w) > 0)
          EXPECT_NEAR(ggx.PdfReflect(ToF(wo), ToF(w)) * 4 * Dot(wo, w), ref.VisibleNormalPdf(wo, w),
                      rounding * ref.VisibleNormalPdf(wo, w));
      }
  }
}

// Heitz 2014 section 6 ("weak white furnace"): the visible normals' density
// integrates to one, i.e. the integral over wi of D(h) G1(wo) / (4 wo.z) is
// 1. For the reference D and G1 (so that the formulas the other tests rely
// on are right) and for the code's.
TEST(GGX, WeakWhiteFurnace) {
  double worstReference = 0, worstCode = 0;
  for (double roughness : {0.1, 0.3, 0.6, 1.0})
    for (double cosO : {1.0, 0.7, 0.3, 0.1, 0.02}) {
      const ReferenceBSDF ref = ReferenceBSDF::Make({1, 1, 1}, roughness, 0);
      const GGX ggx{(float)ref.alpha};
      const D3 wo = OutgoingAt(cosO);
      double reference = 0, code = 0;
      VisibleNormalQuadrature(wo, ref.alpha, [&](D3 h, double w) {
        reference += w * ref.VisibleNormalPdf(wo, h);
        code += w * ggx.G1(ToF(wo)) * std::max(0.0, Dot(wo, h)) * ggx.D(ToF(h)) / wo.z;
      });
      EXPECT_NEAR(reference, 1.0, 1e-6) << "roughness " << roughness << " cos " << cosO;
      EXPECT_NEAR(code, 1.0, SpecularFloatTolerance(ref.alpha)) << "roughness " << roughness << " cos " << cosO;
      worstReference = std::max(worstReference, std::fabs(reference - 1));
      worstCode = std::max(worstCode, std::fabs(code - 1));
    }
  std::printf("weak white furnace: largest |integral - 1| %.2e (reference), %.2e (code, float)\n", worstReference,
              worstCode);
}

// The quadrature's own accuracy, on integrals known in closed form: the
// cosine lobe over the upper hemisphere is 1; the solid angle above the
// horizon 2 pi.
TEST(Quadrature, IsExactOnKnownIntegrals) {
  for (double alpha : {0.01, 0.1, 1.0})
    for (double cosO : {1.0, 0.5, 0.05}) {
      double cosine = 0, solidAngle = 0;
      ReflectedDirectionQuadrature(OutgoingAt(cosO), alpha, [&](D3 wi, double w) {
        cosine += w * wi.z / kPiD;
        solidAngle += w;
      });
      EXPECT_NEAR(cosine, 1.0, 1e-9) << alpha << " " << cosO;
      EXPECT_NEAR(solidAngle, 2 * kPiD, 1e-8) << alpha << " " << cosO;
    }
}

// ---------------------------------------------------------------------------
// Sampling against densities (chi-square, as pbrt-v4's bsdfs_test.cpp and
// Mitsuba's chi2 tests). False failure 1e-4 per test, split over its cases.

void ReportChiSquare(const char* what, const ChiSquareOutcome& r) {
  std::printf("%s: chi^2 %.1f (limit %.1f, %d dof), power: a density off by %.2f %% fails\n", what, r.statistic,
              r.limit, r.dof, 100 * r.power);
  EXPECT_TRUE(r.Passes()) << what;
  EXPECT_LE(r.power, kRequiredPower) << what;
}

TEST(Sampling, CosineHemisphereMatchesCosOverPi) {
  // Bins of equal probability: t = sin^2(theta) is the cosine lobe's CDF.
  const ChiSquareOutcome r = ChiSquareOnHemisphere(
      [](PCG32& rng, D3* w) {
        const float u0 = rng.Uniform(), u1 = rng.Uniform();
        *w = FromF(SampleCosineHemisphere(u0, u1));
        return true;
      },
      [](D3 w) { return w.z > 0 ? w.z / kPiD : 0; }, [](double t) { return std::asin(std::sqrt(t)); }, 1000000,
      kFalseFailure);
  ReportChiSquare("cosine lobe", r);
}

// GGX's visible-normal sampler against Heitz 2018's density, down to the
// lowest roughness (bins follow GGX's warp) and to grazing wo; and the
// reflected directions against D_wo(h) / (4 wo.h), where rough enough for
// bins uniform in cos(theta).
TEST(Sampling, GGXVisibleNormalsMatchHeitz2018) {
  const std::vector<double> roughnesses{0.1, 0.3, 1.0}, cosines{1.0, 0.5, 0.05};
  const double perCase = kFalseFailure / (roughnesses.size() * cosines.size() * 2);
  for (double roughness : roughnesses)
    for (double cosO : cosines) {
      const ReferenceBSDF ref = ReferenceBSDF::Make({1, 1, 1}, roughness, 0);
      const GGX ggx{(float)ref.alpha};
      const D3 wo = OutgoingAt(cosO);
      char what[128];
      std::snprintf(what, sizeof what, "GGX visible normals, roughness %.1f, cos_o %.2f", roughness, cosO);
      ReportChiSquare(what, ChiSquareOnHemisphere(
                                [&](PCG32& rng, D3* h) {
                                  const float u0 = rng.Uniform(), u1 = rng.Uniform();
                                  *h = FromF(ggx.SampleVisibleNormal(ToF(wo), u0, u1));
                                  return true;
                                },
                                [&](D3 h) { return ref.VisibleNormalPdf(wo, h); },
                                [&](double t) { return GGXTheta(ref.alpha, t); }, 1000000, perCase));
      if (roughness < 0.3) continue;
      std::snprintf(what, sizeof what, "GGX reflected directions, roughness %.1f, cos_o %.2f", roughness, cosO);
      ReportChiSquare(what, ChiSquareOnHemisphere(
                                [&](PCG32& rng, D3* wi) {
                                  const float u0 = rng.Uniform(), u1 = rng.Uniform();
                                  const D3 h = FromF(ggx.SampleVisibleNormal(ToF(wo), u0, u1));
                                  *wi = h * (2 * Dot(wo, h)) - wo;
                                  return true;
                                },
                                [&](D3 wi) { return ref.ReflectedPdf(wo, wi); },
                                [](double t) { return std::acos(1 - t); }, 1000000, perCase, 30, 60));
    }
}

// The whole BSDF: Sample's directions against Pdf (the mixture of both
// lobes), as the integrator uses them.
TEST(Sampling, BSDFSamplesItsPdf) {
  const std::vector<float> roughnesses{0.35f, 1.f}, metallics{0.f, 1.f}, cosines{0.9f, 0.4f};
  const double perCase = kFalseFailure / (roughnesses.size() * metallics.size() * cosines.size());
  for (float roughness : roughnesses)
    for (float metallic : metallics)
      for (float cosO : cosines) {
        const D3 wo = OutgoingAt(cosO);
        const ReferenceBSDF ref = ReferenceBSDF::Make({0.8, 0.6, 0.4}, roughness, metallic);
        const SurfaceBSDF bsdf = CodeBSDF(ref, wo, roughness);
        char what[128];
        std::snprintf(what, sizeof what, "BSDF, roughness %.2f, metallic %.0f, cos_o %.1f", roughness, metallic, cosO);
        ReportChiSquare(what, ChiSquareOnHemisphere(
                                  [&](PCG32& rng, D3* w) {
                                    const float a = rng.Uniform(), b = rng.Uniform(), c = rng.Uniform();
                                    const BSDFSample s = bsdf.Sample(ToF(wo), a, b, c);
                                    *w = FromF(s.wi);
                                    return s.pdf > 0.f;
                                  },
                                  [&](D3 w) { return bsdf.Pdf(ToF(wo), ToF(w)); },
                                  [](double t) { return std::acos(1 - t); }, 1000000, perCase, 30, 60));
      }
}

// ---------------------------------------------------------------------------
// Deterministic integrals.

// The BSDF's pdf integrates to the probability that Sample returns a
// direction: 1 minus the specular lobe's share of reflections below the
// horizon, (1 - P_spec) + P_spec * (integral of D_wo(h) / (4 wo.h) above it).
TEST(BSDF, PdfIntegratesToTheProbabilityOfASample) {
  for (float roughness : {0.1f, 0.35f, 0.7f, 1.f})
    for (float metallic : {0.f, 1.f})
      for (double cosO : {1.0, 0.7, 0.3, 0.05}) {
        const D3 wo = OutgoingAt(cosO);
        const ReferenceBSDF ref = ReferenceBSDF::Make({0.8, 0.6, 0.4}, roughness, metallic);
        const SurfaceBSDF bsdf = CodeBSDF(ref, wo, roughness);
        double integral = 0, reflectedAbove = 0;
        ReflectedDirectionQuadrature(wo, ref.alpha, [&](D3 wi, double w) {
          integral += w * bsdf.Pdf(ToF(wo), ToF(wi));
          reflectedAbove += w * ref.ReflectedPdf(wo, wi);
        });
        const double ps = bsdf.SpecularProbability((float)cosO);
        EXPECT_NEAR(integral, (1 - ps) + ps * reflectedAbove, 1e-6 + ps * SpecularFloatTolerance(ref.alpha))
            << "roughness " << roughness << " metallic " << metallic << " cos " << cosO;
        EXPECT_LE(reflectedAbove, 1 + 1e-6);
      }
}

// Each lobe's directional albedo. The code's Eval integrated over wi, less
// the other lobe's reference formula, against the reference: the diffuse
// lobe's albedo is exactly DiffuseWeight(cos_o) (a cosine lobe integrates
// to one); the specular lobe's is the integral of F D G2 / (4 cos_o).
// Deterministic: the tolerance is float rounding (1e-5 of the diffuse
// albedo, SpecularFloatTolerance of the specular one), far above the
// quadrature's error (Quadrature.IsExactOnKnownIntegrals): a change of the
// diffuse lobe by 0.01 % fails, of the specular lobe by 0.01 % from
// roughness 0.35 up (0.1 % at 0.1).
TEST(BSDF, EachLobesAlbedoIsItsIntegral) {
  double worstDiffuse = 0, worstSpecular = 0;
  for (float roughness : {0.1f, 0.35f, 0.7f, 1.f})
    for (float metallic : {0.f, 0.5f, 1.f})
      for (double cosO : {1.0, 0.7, 0.3, 0.1}) {
        const D3 wo = OutgoingAt(cosO);
        const ReferenceBSDF ref = ReferenceBSDF::Make({0.8, 0.6, 0.4}, roughness, metallic);
        const SurfaceBSDF bsdf = CodeBSDF(ref, wo, roughness);
        Rgb3 diffuse{}, specular{}, specularRef{};
        ReflectedDirectionQuadrature(wo, ref.alpha, [&](D3 wi, double w) {
          const Rgb3 code = ToRgb3(bsdf.Eval(ToF(wo), ToF(wi)));
          const Rgb3 d = ref.DiffuseFCos(wo, wi), s = ref.SpecularFCos(wo, wi);
          for (int c = 0; c < 3; ++c) {
            diffuse[c] += w * (code[c] - s[c]);
            specular[c] += w * (code[c] - d[c]);
            specularRef[c] += w * s[c];
          }
        });
        const Rgb3 diffuseRef = ref.DiffuseWeight(cosO);
        for (int c = 0; c < 3; ++c) {
          const double specularRounding = SpecularFloatTolerance(ref.alpha) * specularRef[c];
          EXPECT_NEAR(diffuse[c], diffuseRef[c], 1e-5 * diffuseRef[c] + specularRounding + 1e-7)
              << "diffuse, roughness " << roughness << " metallic " << metallic << " cos " << cosO << " channel " << c;
          EXPECT_NEAR(specular[c], specularRef[c], 1e-5 * diffuseRef[c] + specularRounding + 1e-7)
              << "specular, roughness " << roughness << " metallic " << metallic << " cos " << cosO << " channel " << c;
          if (roughness < 0.3f) continue;  // the float rounding of D (SpecularFloatTolerance)
          if (diffuseRef[c] > 0) worstDiffuse = std::max(worstDiffuse, std::fabs(diffuse[c] / diffuseRef[c] - 1));
          worstSpecular = std::max(worstSpecular, std::fabs(specular[c] / specularRef[c] - 1));
        }
      }
  std::printf(
      "lobe albedos against their integrals, roughness 0.35 to 1: largest relative difference diffuse "
      "%.2e, specular %.2e\n",
      worstDiffuse, worstSpecular);
}

// Energy: with a white base colour the two lobes together reflect at most
// what arrives (the (1 - F0) factor of the diffuse weight is there for this;
// decisions.md), at every roughness and angle. Deterministic.
TEST(BSDF, ConservesEnergy) {
  double most = 0;
  for (float roughness : {0.1f, 0.2f, 0.4f, 0.7f, 1.f})
    for (float metallic : {0.f, 0.5f, 1.f})
      for (double cosO : {1.0, 0.7, 0.4, 0.2, 0.1, 0.03}) {
        const D3 wo = OutgoingAt(cosO);
        const ReferenceBSDF ref = ReferenceBSDF::Make({1, 1, 1}, roughness, metallic);
        const SurfaceBSDF bsdf = CodeBSDF(ref, wo, roughness);
        double albedo = 0, reference = 0;
        ReflectedDirectionQuadrature(wo, ref.alpha, [&](D3 wi, double w) {
          albedo += w * bsdf.Eval(ToF(wo), ToF(wi)).g;
          reference += w * (ref.DiffuseFCos(wo, wi)[1] + ref.SpecularFCos(wo, wi)[1]);
        });
        EXPECT_LE(reference, 1.0 + 1e-6) << "roughness " << roughness << " metallic " << metallic << " cos " << cosO;
        EXPECT_LE(albedo, 1.0 + SpecularFloatTolerance(ref.alpha))
            << "roughness " << roughness << " metallic " << metallic << " cos " << cosO;
        most = std::max(most, reference);
      }
  std::printf("largest directional albedo of a white BSDF: %.6f\n", most);
}

// The albedo the integrator sees: the mean of f cos / pdf over Sample's
// directions (what a path's throughput is multiplied by), against the
// reference lobes' integrals. Statistical: per case and channel a z-test,
// two-sided, false failure 1e-4 over all of them; its power is stated for
// each lobe as the smallest relative change of that lobe alone that fails
// with probability 1 - 1e-4.
TEST(BSDF, SampledAlbedoIsTheIntegral) {
  struct Case {
    float roughness, metallic;
    double cosO;
  };
  const std::vector<Case> cases{{0.5f, 0.f, 1.0}, {0.5f, 0.f, 0.5}, {0.2f, 0.f, 0.8}, {1.f, 0.f, 0.2},
                                {0.3f, 1.f, 0.9}, {0.6f, 1.f, 0.4}, {0.6f, 0.5f, 0.7}};
  const int n = 400000;
  const double zLimit = NormalQuantile(1 - kFalseFailure / (2 * 3 * cases.size())),
               zPower = NormalQuantile(1 - kFalseFailure);
  double bestDiffusePower = 1, bestSpecularPower = 1;
  for (const Case& k : cases) {
    const D3 wo = OutgoingAt(k.cosO);
    const ReferenceBSDF ref = ReferenceBSDF::Make({0.8, 0.6, 0.4}, k.roughness, k.metallic);
    const SurfaceBSDF bsdf = CodeBSDF(ref, wo, k.roughness);
    Rgb3 specularRef{};
    ReflectedDirectionQuadrature(wo, ref.alpha, [&](D3 wi, double w) {
      const Rgb3 s = ref.SpecularFCos(wo, wi);
      for (int c = 0; c < 3; ++c) specularRef[c] += w * s[c];
    });
    const Rgb3 diffuseRef = ref.DiffuseWeight(k.cosO);
    std::array<MeanEstimate, 3> estimate;
    PCG32 rng(23, 9);
    for (int i = 0; i < n; ++i) {
      const float a = rng.Uniform(), b = rng.Uniform(), c = rng.Uniform();
      const BSDFSample s = bsdf.Sample(ToF(wo), a, b, c);
      for (int ch = 0; ch < 3; ++ch) estimate[ch].Add(s.pdf > 0.f ? s.f_cos[ch] / s.pdf : 0.0);
    }
    for (int c = 0; c < 3; ++c) {
      const double expected = diffuseRef[c] + specularRef[c], se = estimate[c].StandardError();
      const double z = (estimate[c].Mean() - expected) / se;
      const double bias = (zLimit + zPower) * se;  // the smallest that fails with probability 1 - 1e-4
      const double diffusePower = diffuseRef[c] > 0 ? bias / diffuseRef[c] : INFINITY,
                   specularPower = bias / specularRef[c];
      std::printf(
          "roughness %.1f metallic %.1f cos_o %.1f channel %d: sampled albedo %.5f, integral %.5f "
          "(diffuse %.5f + specular %.5f), z %+.2f (limit %.2f); power: diffuse lobe %.2f %%, specular "
          "lobe %.2f %%\n",
          k.roughness, k.metallic, k.cosO, c, estimate[c].Mean(), expected, diffuseRef[c], specularRef[c], z, zLimit,
          100 * diffusePower, 100 * specularPower);
      EXPECT_LE(std::fabs(z), zLimit) << "roughness " << k.roughness << " metallic " << k.metallic << " cos " << k.cosO
                                      << " channel " << c;
      bestDiffusePower = std::min(bestDiffusePower, diffusePower);
      bestSpecularPower = std::min(bestSpecularPower, specularPower);
    }
  }
  EXPECT_LE(bestDiffusePower, kRequiredPower);
  EXPECT_LE(bestSpecularPower, kRequiredPower);
}

// Reciprocity. The specular lobe is reciprocal: F(wo.h) D(h) G2(wo, wi) /
// (4 cos_o cos_i) is symmetric, since wo.h = wi.h. The diffuse lobe is not:
// its weight 1 - F(cos_o) depends on wo alone (decisions.md says why), so
// f(wo, wi) - f(wi, wo) = (DiffuseWeight(cos_o) - DiffuseWeight(cos_i)) / pi
// exactly. Deterministic; the asymmetry is printed.
TEST(BSDF, SpecularLobeIsReciprocalDiffuseLobeIsNot) {
  std::vector<D3> directions;
  for (double theta : {0.0, 0.35, 0.7, 1.05, 1.3, 1.45})
    for (double phi : {0.0, 1.3, 3.1, 4.4}) directions.push_back(Spherical(theta, phi));
  for (float roughness : {0.2f, 0.5f, 1.f})
    for (float metallic : {0.f, 0.5f, 1.f}) {
      const ReferenceBSDF ref = ReferenceBSDF::Make({0.8, 0.6, 0.4}, roughness, metallic);
      const SurfaceBSDF bsdf = CodeBSDF(ref, {0, 0, 1}, roughness);
      for (D3 wo : directions)
        for (D3 wi : directions) {
          const Rgb3 a = ToRgb3(bsdf.Eval(ToF(wo), ToF(wi))), b = ToRgb3(bsdf.Eval(ToF(wi), ToF(wo)));
          const Rgb3 dOut = ref.DiffuseWeight(wo.z), dIn = ref.DiffuseWeight(wi.z);
          for (int c = 0; c < 3; ++c) {
            const double fa = a[c] / wi.z, fb = b[c] / wo.z;  // f(wo, wi), f(wi, wo)
            EXPECT_NEAR(fa - fb, (dOut[c] - dIn[c]) / kPiD, 2e-5 * std::max(fa, fb) + 1e-7)
                << "roughness " << roughness << " metallic " << metallic << " cos_o " << wo.z << " cos_i " << wi.z;
          }
        }
    }
  // The size of the asymmetry: f(normal, wi) / f(wi, normal) for a grey
  // dielectric, diffuse lobe alone and the whole BSDF (roughness 0.5).
  const ReferenceBSDF ref = ReferenceBSDF::Make({0.8, 0.8, 0.8}, 0.5, 0);
  const SurfaceBSDF bsdf = CodeBSDF(ref, {0, 0, 1}, 0.5f);
  const D3 normal{0, 0, 1};
  for (double cosI : {0.9, 0.5, 0.2, 0.1, 0.05}) {
    const D3 wi = OutgoingAt(cosI);
    const double diffuse = ref.DiffuseWeight(1)[1] / ref.DiffuseWeight(cosI)[1];
    const double whole = (bsdf.Eval(ToF(normal), ToF(wi)).g / cosI) / (bsdf.Eval(ToF(wi), ToF(normal)).g / 1.0);
    std::printf("asymmetry at cos %.2f and the normal: f(n, wi) / f(wi, n) = %.3f (diffuse lobe %.3f)\n", cosI, whole,
                diffuse);
  }
}

TEST(BSDF, BackSideLightIsAbsorbed) {
  const Vec3 normal{0.f, 0.f, 1.f};
  const Vec3 wo = Normalize(Vec3{0.3f, 0.f, 1.f});
  SurfaceBSDF bsdf = SurfaceBSDF::Make(normal, wo, RGB(1.f), 0.5f, 0.f);
  EXPECT_TRUE(bsdf.Eval(wo, Normalize(Vec3{0.2f, 0.1f, -1.f})).IsBlack());
  EXPECT_EQ(bsdf.Pdf(wo, Normalize(Vec3{0.2f, 0.1f, -1.f})), 0.f);
  EXPECT_FALSE(bsdf.Eval(wo, Normalize(Vec3{0.2f, 0.1f, 1.f})).IsBlack());
  // Seen from the other side, the normal turns toward the viewer.
  SurfaceBSDF flipped = SurfaceBSDF::Make(normal, -wo, RGB(1.f), 0.5f, 0.f);
  EXPECT_FALSE(flipped.Eval(-wo, Normalize(Vec3{0.2f, 0.1f, -1.f})).IsBlack());
}

// ---------------------------------------------------------------------------
// Henyey-Greenstein.

// Directions about -wo (the direction of travel): wi at cos(theta) = mu.
D3 AboutTravel(D3 wo, double mu, double phi) {
  const Frame f = Frame::FromZ(ToF(wo * -1.0));
  const double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  return FromF(f.FromLocal(ToF({s * std::cos(phi), s * std::sin(phi), mu})));
}

// HG's mean cosine between the direction of travel and the scattered one is
// g (forward for g > 0): integrated (deterministic, 1e-5) and as the mean of
// sampled directions (a z-test: false failure 1e-4 over the cases; power:
// the smallest error in the mean cosine that fails with probability
// 1 - 1e-4, asserted below 0.03). A flipped sign of g moves it by 2|g|.
TEST(Phase, HenyeyGreensteinMeanCosineIsG) {
  const D3 wo = Normalized({0.3, -0.2, 0.9});
  const std::vector<float> gs{-0.7f, -0.3f, 0.f, 0.3f, 0.8f, 0.95f};
  static const GaussLegendre gl(8);
  std::vector<double> edges;
  for (int k = 0; k <= 4000; ++k) edges.push_back(-1 + 2.0 * k / 4000);
  const double zLimit = NormalQuantile(1 - kFalseFailure / (2 * gs.size())), zPower = NormalQuantile(1 - kFalseFailure);
  for (const float& g : gs) {
    const HGPhaseFunction phase{g};
    double integral = 0, meanCosine = 0, reciprocity = 0;
    PanelNodes(edges, gl, [&](double mu, double w) {
      const D3 wi = AboutTravel(wo, mu, 0.7);
      const double p = phase.p(ToF(wo), ToF(wi));
      integral += 2 * kPiD * w * p;
      meanCosine += 2 * kPiD * w * p * mu;
      reciprocity = std::max(reciprocity, std::fabs(p - phase.p(ToF(wi), ToF(wo))) / p);
    });
    EXPECT_NEAR(integral, 1.0, 1e-5) << "g " << g;
    EXPECT_NEAR(meanCosine, g, 1e-5) << "g " << g;
    EXPECT_LE(reciprocity, 1e-5) << "g " << g;

    MeanEstimate cosine;
    PCG32 rng(31 + (uint64_t)(&g - gs.data()), 3);  // a stream per case: independent z-scores
    for (int i = 0; i < 200000; ++i) {
      const float u0 = rng.Uniform(), u1 = rng.Uniform();
      cosine.Add(Dot(-ToF(wo), phase.Sample(ToF(wo), u0, u1).wi));
    }
    const double z = (cosine.Mean() - g) / cosine.StandardError(), power = (zLimit + zPower) * cosine.StandardError();
    std::printf(
        "HG g %+.2f: integrated mean cosine %+.6f, sampled %+.5f (z %+.2f, limit %.2f); power: an error "
        "of %.4f in the mean cosine fails\n",
        g, meanCosine, cosine.Mean(), z, zLimit, power);
    EXPECT_LE(std::fabs(z), zLimit) << "g " << g;
    EXPECT_LE(power, 0.03);
  }
}

}  // namespace
}  // namespace mmrtm
