// The low-discrepancy pairs of mmrtm/sobol.h: the fast Sobol' dimension 1
// against its generator matrix, the (0, k, 2)-net of every power-of-two
// prefix of each replicate, the replicates' independence (what Film::Noise
// needs), uniform points over scrambles (so estimators stay unbiased), no
// correlation between the pairs of a sample, a smaller integration error
// than independent numbers, and the reuse of one uniform for a sequence of
// choices (mmrtm/integrator.h ChooseAndReuse).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "mmrtm/integrator.h"
#include "mmrtm/sobol.h"

namespace mmrtm {
namespace {

// Sobol' dimension 1 from its direction numbers, one index bit at a time.
uint32_t SobolDimension1Reference(uint32_t index) {
  uint32_t x = 0, column = 0x80000000u;
  for (; index; index >>= 1, column ^= column >> 1)
    if (index & 1u) x ^= column;
  return x;
}

TEST(SobolSampler, Dimension1MatchesItsGeneratorMatrix) {
  PCG32 rng(7, 0);
  for (uint32_t i = 0; i < 100000; ++i) {
    const uint32_t index = i < 50000 ? i : rng.NextU32();
    ASSERT_EQ(ReverseBits32(SobolDimension1Reversed(index)), SobolDimension1Reference(index)) << "index " << index;
  }
  // The first points: 0, 1/2, 3/4, 1/4, 3/8 ... (Joe and Kuo's dimension 2).
  EXPECT_EQ(ReverseBits32(SobolDimension1Reversed(1)), 0x80000000u);
  EXPECT_EQ(ReverseBits32(SobolDimension1Reversed(2)), 0xc0000000u);
  EXPECT_EQ(ReverseBits32(SobolDimension1Reversed(3)), 0x40000000u);
}

// Whether points form a (0, k, 2)-net: every box of 2^a x 2^b equal parts,
// a + b = k, holds exactly one.
bool IsNet(const std::vector<float>& x, const std::vector<float>& y, int k) {
  const size_t n = size_t(1) << k;
  if (x.size() != n) return false;
  for (int a = 0; a <= k; ++a) {
    const int b = k - a;
    std::vector<int> count(n, 0);
    for (size_t i = 0; i < n; ++i) {
      const int bx = (int)(x[i] * (float)(1 << a)), by = (int)(y[i] * (float)(1 << b));
      if (++count[(size_t)bx * ((size_t)1 << b) + (size_t)by] > 1) return false;
    }
  }
  return true;
}

// Sample indices 0, 2, 4 ... are replicate 0, indices 1, 3, 5 ... replicate 1.
TEST(SobolSampler, EveryPowerOfTwoPrefixOfAReplicateIsANet) {
  for (uint64_t pixel : {0ull, 1ull, 12345ull, 999999ull})
    for (int pair = 0; pair < 12; ++pair)
      for (uint32_t replicate : {0u, 1u})
        for (int k = 0; k <= 10; ++k) {
          std::vector<float> x, y;
          for (uint32_t i = 0; i < (1u << k); ++i) {
            float u0, u1;
            ASSERT_EQ(SobolReplicate(2 * i + replicate), replicate);
            SobolPairs(3, pixel, 2 * i + replicate).Get(pair, &u0, &u1);
            ASSERT_GE(u0, 0.f);
            ASSERT_LT(u0, 1.f);
            ASSERT_GE(u1, 0.f);
            ASSERT_LT(u1, 1.f);
            x.push_back(u0);
            y.push_back(u1);
          }
          EXPECT_TRUE(IsNet(x, y, k)) << "pixel " << pixel << " pair " << pair << " replicate " << replicate
                                      << " first " << (1 << k);
        }
}

// The two replicates of a pixel are independently scrambled nets: their
// errors on a smooth integrand (32 points each) are uncorrelated over 4000
// pixels. The sample correlation of independent errors has a standard
// deviation of 1 / sqrt(4000) = 0.016; one scramble shared by both (the
// odd points then fill the even points' gaps) correlates them strongly
// negatively, and the test shows it can fail by measuring that case too.
TEST(SobolSampler, ReplicatesAreIndependentEstimates) {
  auto f = [](double x, double y) { return std::exp(x) * std::sin(3 * y) + x * y; };
  const double exact = (std::exp(1.0) - 1) * (1 - std::cos(3.0)) / 3 + 0.25;
  auto correlation = [&](bool sharedScramble) {
    const int pixels = 4000, n = 32;
    double s00 = 0, s11 = 0, s01 = 0;
    for (int pixel = 0; pixel < pixels; ++pixel) {
      double e[2] = {0, 0};
      for (uint32_t r = 0; r < 2; ++r)
        for (uint32_t i = 0; i < (uint32_t)n; ++i) {
          float u0, u1;
          // Shared: both halves of one replicate's first 64 points.
          const uint32_t index = sharedScramble ? 2 * (r * n + i) : 2 * i + r;
          SobolPairs(8, (uint64_t)pixel, index).Get(kPairFirstVertex, &u0, &u1);
          e[r] += (f(u0, u1) - exact) / n;
        }
      s00 += e[0] * e[0];
      s11 += e[1] * e[1];
      s01 += e[0] * e[1];
    }
    return s01 / std::sqrt(s00 * s11);
  };
  EXPECT_LT(std::fabs(correlation(false)), 0.08);
  EXPECT_LT(correlation(true), -0.3) << "halves of one net are anti-correlated; the check above would see it";
}

TEST(SobolSampler, SameNumbersForTheSameSampleOnly) {
  float a0, a1, b0, b1;
  SobolPairs(5, 77, 9).Get(3, &a0, &a1);
  SobolPairs(5, 77, 9).Get(3, &b0, &b1);
  EXPECT_EQ(a0, b0);
  EXPECT_EQ(a1, b1);
  std::set<float> seen;  // another seed, pixel, index or pair: other numbers
  for (SobolPairs p : {SobolPairs(5, 77, 9), SobolPairs(6, 77, 9), SobolPairs(5, 78, 9), SobolPairs(5, 77, 10)})
    for (int pair = 3; pair <= 4; ++pair) {
      p.Get(pair, &a0, &a1);
      seen.insert(a0);
    }
  EXPECT_EQ(seen.size(), 8u);
}

// Over scrambles (pixels), one sample's point is uniform on the square: a
// chi-square test on 8 x 8 cells. n = 64000, 63 degrees of freedom: the
// statistic has mean 63 and standard deviation 11.2; 130 is six of them.
TEST(SobolSampler, PointsAreUniformOverScrambles) {
  for (uint32_t index : {0u, 5u, 1000u})
    for (int pair : {0, 4}) {
      std::vector<int> cells(64, 0);
      const int n = 64000;
      for (int pixel = 0; pixel < n; ++pixel) {
        float u0, u1;
        SobolPairs(1, (uint64_t)pixel, index).Get(pair, &u0, &u1);
        ++cells[(int)(u0 * 8) * 8 + (int)(u1 * 8)];
      }
      double chi2 = 0;
      for (int c : cells) chi2 += (c - n / 64.0) * (c - n / 64.0) / (n / 64.0);
      EXPECT_LT(chi2, 130.0) << "sample " << index << " pair " << pair;
    }
}

// The pairs of one sample are not correlated: over a pixel's 64 samples,
// pair 0's first coordinate and pair 2's fall in the same half about half
// of the time. Independent halves: 32 of 64 +- 4 per pixel, a mean absolute
// deviation of 3.2 over many pixels; an index shared between pairs (or
// XORed by a constant) makes every pixel 0 or 64, a deviation of 32.
TEST(SobolSampler, PairsOfASampleAreDecorrelated) {
  double deviation = 0;
  const int pixels = 2000;
  for (int pixel = 0; pixel < pixels; ++pixel) {
    int same = 0;
    for (uint32_t i = 0; i < 64; ++i) {
      float a0, a1, b0, b1;
      SobolPairs pairs(2, (uint64_t)pixel, i);
      pairs.Get(0, &a0, &a1);
      pairs.Get(2, &b0, &b1);
      same += (a0 < 0.5f) == (b0 < 0.5f);
    }
    deviation += std::fabs(same - 32.0);
  }
  deviation /= pixels;
  EXPECT_GT(deviation, 2.0);
  EXPECT_LT(deviation, 4.5);
}

// A smooth integrand over the unit square, 64 points per trial, 2000 trials
// (pixels): the mean squared error of the pairs is far below that of
// independent numbers (scrambled nets: about N^-3 against N^-1), and both
// means are unbiased within five standard errors.
TEST(SobolSampler, IntegratesASmoothFunctionBetterThanIndependentNumbers) {
  auto f = [](double x, double y) { return std::exp(x) * std::sin(3 * y) + x * y; };
  const double exact = (std::exp(1.0) - 1) * (1 - std::cos(3.0)) / 3 + 0.25;
  const int trials = 2000, n = 64;
  double mseSobol = 0, mseIndependent = 0, biasSobol = 0, biasIndependent = 0;
  for (int t = 0; t < trials; ++t) {
    double sumSobol = 0, sumIndependent = 0;
    PCG32 rng = PixelSampleRNG(4, (uint64_t)t, 0);
    for (uint32_t i = 0; i < (uint32_t)n; ++i) {
      float u0, u1;
      SobolPairs(4, (uint64_t)t, i).Get(kPairFirstVertex + kPairLight, &u0, &u1);
      sumSobol += f(u0, u1);
      const float v0 = rng.Uniform(), v1 = rng.Uniform();
      sumIndependent += f(v0, v1);
    }
    const double es = sumSobol / n - exact, ei = sumIndependent / n - exact;
    mseSobol += es * es / trials;
    mseIndependent += ei * ei / trials;
    biasSobol += es / trials;
    biasIndependent += ei / trials;
  }
  EXPECT_LT(mseSobol, 0.05 * mseIndependent);
  EXPECT_LT(std::fabs(biasIndependent), 5 * std::sqrt(mseIndependent / trials));
  // The nets' own tiny error; the float's 24 bits leave ~1e-7.
  EXPECT_LT(std::fabs(biasSobol), 5 * std::sqrt(mseSobol / trials) + 1e-6);
}

// One uniform for a sequence of choices: each choice has its probability,
// and the uniform handed on is uniform again (stratified numbers give
// stratified numbers).
TEST(SobolSampler, ChooseAndReuseKeepsTheUniform) {
  const int n = 100000;
  int chosen = 0;
  std::vector<int> after(10, 0);
  for (int i = 0; i < n; ++i) {
    float u = ((float)i + 0.5f) / (float)n;
    if (ChooseAndReuse(0.3f, &u)) ++chosen;
    ASSERT_GE(u, 0.f);
    ASSERT_LT(u, 1.f);
    ++after[(int)(u * 10)];
  }
  EXPECT_NEAR(chosen, 0.3 * n, 2);
  for (int c : after) EXPECT_NEAR(c, n / 10, 3);
  float u = 0.999f;  // p = 1 keeps it in [0, 1)
  EXPECT_TRUE(ChooseAndReuse(1.f, &u));
  EXPECT_LT(u, 1.f);
}

}  // namespace
}  // namespace mmrtm
