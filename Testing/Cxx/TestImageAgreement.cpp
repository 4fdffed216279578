// The image comparison of ImageAgreement.h holds what it states, on
// synthetic images whose truth is known: two unbiased estimates fail with
// probability near falseFailure (its limits come from the statistics'
// distributions, not from tuning), and a bias of the reported power fails
// with probability 1 - falseFailure. The samples are heavy-tailed and the
// channels move together, as a path tracer's do: a path reaches a light
// (an exponential amount of it) or does not.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "ImageAgreement.h"

namespace mmrtm::test {
namespace {

TEST(ImageAgreement, NormalQuantile) {
  EXPECT_NEAR(NormalQuantile(0.975), 1.959963984540054, 1e-12);
  EXPECT_NEAR(NormalQuantile(1 - 1e-4), 3.719016485455709, 1e-10);
  EXPECT_NEAR(NormalQuantile(1e-6), -4.753424308822899, 1e-10);
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-15);
  EXPECT_THROW(NormalQuantile(0.0), std::invalid_argument);
}

// An image of W x H pixels whose pixel p has true mean level[p] x (1, 0.8,
// 0.6), estimated as R replicates of n samples each; each sample reaches a
// light with probability 0.3, bringing Exp(1) of it (and 0 otherwise).
struct SyntheticScene {
  int width = 16, height = 16, replicates = 8, samples = 4;
  std::vector<double> level;

  explicit SyntheticScene(uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.2, 1.0);
    for (int p = 0; p < width * height; ++p) level.push_back(u(rng));
  }

  // `bias`: every value also gets bias x its true mean (a biased estimator
  // with the unbiased one's variance).
  ImageEstimate Estimate(std::mt19937_64& rng, double bias = 0.0) const {
    std::bernoulli_distribution hit(0.3);
    std::exponential_distribution<double> amount(1.0);
    const double channel[3] = {1.0, 0.8, 0.6};
    std::vector<std::vector<float>> images(replicates, std::vector<float>(3 * level.size()));
    for (auto& image : images)
      for (size_t p = 0; p < level.size(); ++p) {
        double sum = 0;
        for (int s = 0; s < samples; ++s) sum += hit(rng) ? amount(rng) / 0.3 : 0.0;
        for (int c = 0; c < 3; ++c) image[3 * p + c] = (float)(level[p] * channel[c] * (sum / samples + bias));
      }
    return FromReplicates(images, width, height);
  }
};

TEST(ImageAgreement, FalseFailuresAndPowerAreAsStated) {
  // A looser false-failure level than the tests' 1e-4, so that a few
  // thousand trials can measure it: 0.01, expected 30 failures in 3000.
  const int trials = 3000;
  AgreementOptions options;
  options.falseFailure = 0.01;
  const SyntheticScene scene(1);
  std::mt19937_64 rng(2);
  int failures = 0, globalFailures = 0, blockFailures = 0;
  double sumZ2 = 0, power = 0;
  for (int t = 0; t < trials; ++t) {
    const ImageEstimate a = scene.Estimate(rng), b = scene.Estimate(rng);
    const Agreement r = Compare(a, b, options);
    failures += !r.Agrees();
    globalFailures += !r.GlobalAgrees();
    blockFailures += !r.BlocksAgree();
    for (double z : r.globalZ) sumZ2 += z * z / 3;
    power += r.power / trials;
  }
  std::printf(
      "%d trials at false-failure level %.3f: %d failed (global %d, blocks %d); mean global z^2 %.3f; "
      "mean power %.2f %%\n",
      trials, options.falseFailure, failures, globalFailures, blockFailures, sumZ2 / trials, 100 * power);
  // Binomial(3000, 0.01): 30 +- 5.4; the bounds are over 3.5 standard deviations out.
  EXPECT_GE(failures, 11);
  EXPECT_LE(failures, 50);
  EXPECT_NEAR(sumZ2 / trials, 1.0, 0.1) << "the global z is N(0, 1) under agreement";

  // At a bias equal to the power the test fails with probability 1 - 0.01
  // (the power is computed for that level here): 300 trials, at most 3
  // pass in expectation; more than 12 would mean the power is overstated.
  int passes = 0;
  for (int t = 0; t < 300; ++t) {
    const ImageEstimate a = scene.Estimate(rng, power), b = scene.Estimate(rng);
    passes += Compare(a, b, options).Agrees();
  }
  std::printf("a bias of the power (%.2f %%): %d of 300 passed\n", 100 * power, passes);
  EXPECT_LE(passes, 12);
}

TEST(ImageAgreement, NoiselessPixelsMustAgreeExactly) {
  ImageEstimate a;
  a.width = a.height = 4;
  a.mean.assign(a.Values(), 0.5);
  a.variance.assign(a.Values(), 0.0);
  ImageEstimate b = a;
  EXPECT_TRUE(Compare(a, b).Agrees());
  b.mean[7] = 0.5001;
  const Agreement r = Compare(a, b);
  EXPECT_FALSE(r.Agrees());
  EXPECT_EQ(r.noiselessBlocksThatDiffer, 1u);
  EXPECT_THROW(Compare(a, Scaled(ImageEstimate{}, 1.0)), std::invalid_argument);
}

}  // namespace
}  // namespace mmrtm::test
