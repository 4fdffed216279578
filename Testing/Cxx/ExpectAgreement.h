// GoogleTest checks on ImageAgreement.h's comparison, with the scores
// printed so that a run shows each comparison's power.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "ImageAgreement.h"

namespace mmrtm::test {

// a and b estimate one image (fails with probability below 1e-4 when they
// do), and the comparison would see a change of a channel's covered-pixel
// mean by `maxPower` (with probability 1 - 1e-4).
inline Agreement ExpectAgreement(const std::string& what, const ImageEstimate& a, const ImageEstimate& b,
                                 double maxPower = 0.02) {
  const Agreement r = Compare(a, b);
  std::printf("%s: %s\n", what.c_str(), r.Describe().c_str());
  EXPECT_TRUE(r.Agrees()) << what << ": the images differ beyond their noise: " << r.Describe();
  EXPECT_LE(r.power, maxPower) << what << ": too weak to see a " << 100 * maxPower << " % bias: " << r.Describe();
  return r;
}

// a and b differ beyond their noise (a planted bias must be seen).
inline Agreement ExpectDisagreement(const std::string& what, const ImageEstimate& a, const ImageEstimate& b) {
  const Agreement r = Compare(a, b);
  std::printf("%s: %s\n", what.c_str(), r.Describe().c_str());
  EXPECT_FALSE(r.Agrees()) << what << ": passed as the same image: " << r.Describe();
  return r;
}

// A Monte Carlo estimate of a value known exactly (its mean, and its
// standard error from independent samples) lies within kExactSigmas
// standard errors of it (plus `slack` for float rounding). An unbiased
// estimator fails one such check with probability 6.8e-6 (normal,
// two-sided), so a test of up to 14 of them below 1e-4; a bias of
// (kExactSigmas + 3.72) standard errors, the check's power (printed, as a
// fraction of the exact value), fails with probability 1 - 1e-4.
constexpr double kExactSigmas = 4.5;
inline void ExpectUnbiased(double mean, double standardError, double exact, const std::string& what, double slack = 0) {
  const double power = (kExactSigmas + NormalQuantile(1 - 1e-4)) * standardError / std::fabs(exact);
  std::printf("%s: %.6g +- %.2g against %.6g (z %+.2f; power %.2f %%)\n", what.c_str(), mean, standardError, exact,
              standardError > 0 ? (mean - exact) / standardError : 0.0, 100 * power);
  EXPECT_NEAR(mean, exact, kExactSigmas * standardError + slack) << what << " (power " << 100 * power << " %)";
}

}  // namespace mmrtm::test
