// Sample-parallel rendering (the ParaView plugin under MPI) combines films
// of independent sample streams by summing Film::Moments(). The combined
// film must be the film of all their samples: the same mean and variance
// as one film fed every sample, and, for renders, agree with a serial
// render of as many samples within noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "TestSceneHelpers.h"
#include "cpu_renderer.h"

namespace mmrtm {
namespace {

std::vector<double> Sum(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> s(a.size());
  for (size_t i = 0; i < a.size(); ++i) s[i] = a[i] + b[i];
  return s;
}

TEST(FilmMoments, CombinedFilmIsTheFilmOfAllSamples) {
  // Films of 3 and 5 samples a pixel, and one film fed all 8.
  const int w = 4, h = 3;
  Film a(w, h), b(w, h), all(w, h);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 10.f);
  // Per pixel, the luminance sums and counts of each film's replicates
  // (even and odd sample indices of that film).
  std::vector<double> replicateSum[2], replicateCount[2];
  for (int r = 0; r < 2; ++r) replicateSum[r].assign(w * h, 0.0), replicateCount[r].assign(w * h, 0.0);
  auto feed = [&](Film& film, Film& whole, int samples) {
    for (int s = 1; s <= samples; ++s) {
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const RGB L(u(rng), u(rng), u(rng));
          const int replicate = (int)(film.Samples() % 2);
          replicateSum[replicate][y * w + x] += Luminance(L);
          replicateCount[replicate][y * w + x] += 1;
          const float alpha = u(rng) / 10.f;
          film.View().AddSample(x, y, L, alpha, film.Samples() + 1);
          whole.View().AddSample(x, y, L, alpha, whole.Samples() + 1);
        }
      film.AddSamples(1);
      whole.AddSamples(1);
    }
  };
  feed(a, all, 3);
  feed(b, all, 5);
  const Film combined = Film::FromMoments(w, h, a.Samples() + b.Samples(), Sum(a.Moments(), b.Moments()));
  ASSERT_EQ(8u, combined.Samples());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(all.Mean(x, y)[c], combined.Mean(x, y)[c], 1e-4f);
        EXPECT_NEAR(all.VarianceOfMean(x, y)[c], combined.VarianceOfMean(x, y)[c], 1e-4f * all.VarianceOfMean(x, y)[c]);
        EXPECT_GT(combined.VarianceOfMean(x, y)[c], 0.f);
      }
      EXPECT_NEAR(all.Alpha(x, y), combined.Alpha(x, y), 1e-5f);
    }
  // The noise from the replicates: each part's even samples with the
  // others' even samples (5 of 8: 2 of a's 3, 3 of b's 5).
  double sumVar = 0;
  for (int i = 0; i < w * h; ++i) {
    const double n0 = replicateCount[0][i], n1 = replicateCount[1][i], n = n0 + n1;
    const double d = replicateSum[0][i] / n0 - replicateSum[1][i] / n1;
    sumVar += d * d * n0 * n1 / (n * n);
  }
  EXPECT_NEAR(std::sqrt(sumVar / (w * h)), combined.Noise().rmsStandardError, 1e-4 * std::sqrt(sumVar / (w * h)));
  // A film through its own moments keeps its noise.
  const Film roundTrip = Film::FromMoments(w, h, b.Samples(), b.Moments());
  EXPECT_NEAR(b.Noise().rmsStandardError, roundTrip.Noise().rmsStandardError, 1e-5 * b.Noise().rmsStandardError);
  // An empty film (a process that rendered nothing) changes nothing.
  const Film same = Film::FromMoments(w, h, a.Samples(), Sum(a.Moments(), Film(w, h).Moments()));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.Mean(1, 2)[c], same.Mean(1, 2)[c], 1e-5f);
  EXPECT_THROW(Film::FromMoments(w + 1, h, 8, combined.Moments()), std::invalid_argument);
}

// Feeds `samples` samples to every pixel of `film`: pixel i's sample s
// (0-based) is sample(i, s).
template <class SampleFn>
void Feed(Film& film, int samples, SampleFn sample) {
  for (int s = 0; s < samples; ++s) {
    for (int i = 0; i < film.Width() * film.Height(); ++i)
      film.View().AddSample(i % film.Width(), i / film.Width(), sample(i, s), 1.f, (uint32_t)s + 1);
    film.AddSamples(1);
  }
}

// The noise a noise target stops on is the standard error of the pixels'
// mean luminance, whatever the colour channels do. Independent samples of
// known variance (exponential, heavy-ish tailed as radiance is), 4000
// pixels of 16: the estimate sums 4000 one-degree-of-freedom terms, so its
// squared value has a relative standard deviation of about
// sqrt(2.4 / 4000) = 0.025 (2.4: the squared difference of two means of 8
// exponentials); the bounds are 5 of those. The channels' covariance
// is not needed: the same holds when they move together and when they are
// independent (where a bound from the channels' own errors overstated the
// error 1.2 times or more).
TEST(FilmNoise, IsTheLuminanceStandardErrorForIndependentSamples) {
  const int w = 80, h = 50, samples = 16;
  const double wr = 0.2126, wg = 0.7152, wb = 0.0722;
  for (bool correlated : {true, false}) {
    Film film(w, h);
    std::mt19937 rng(11);
    std::exponential_distribution<float> u(1.f);
    Feed(film, samples, [&](int, int) {
      const float a = u(rng);
      return correlated ? RGB(a, 0.5f * a, 2.f * a) : RGB(a, u(rng), u(rng));
    });
    // Var of one sample's luminance, then of a pixel's mean of 16.
    const double sampleVar = correlated ? std::pow(wr + 0.5 * wg + 2 * wb, 2) : wr * wr + wg * wg + wb * wb;
    const double meanLum = correlated ? wr + 0.5 * wg + 2 * wb : wr + wg + wb;
    const double trueVar = sampleVar / samples;
    const NoiseEstimate noise = film.Noise();
    EXPECT_NEAR(meanLum, noise.meanLuminance, 0.02 * meanLum);  // 4000 x 16 samples: 0.4 % sd
    const double ratio = noise.rmsStandardError * noise.rmsStandardError / trueVar;
    RecordProperty(correlated ? "ratio_correlated" : "ratio_independent", std::to_string(ratio));
    EXPECT_GT(ratio, 1 - 5 * 0.025) << (correlated ? "channels together" : "channels independent");
    EXPECT_LT(ratio, 1 + 5 * 0.025) << (correlated ? "channels together" : "channels independent");
    EXPECT_NEAR(noise.rmsStandardError / noise.meanLuminance, noise.relative, 1e-12);
  }
}

// Stratified samples, the reason for the two replicates: every sample of
// a pixel is its value plus a replicate's own random offset (sd 0.1) plus
// a stratum's offset of +-1 that cancels within each replicate's 8
// samples, as a net's strata cancel in its mean. The error of the mean is
// only the replicates' offsets, variance 0.01 / 2; the samples' spread
// (VarianceOfMean) says about 1 / 16, 12 times that. The estimate from the
// replicates is the error: within 5 standard deviations (4000 pixels,
// one chi-square degree of freedom each: 0.022) of the true variance and
// of the squared error actually made.
TEST(FilmNoise, IsTheErrorOfStratifiedSamplesNotTheirSpread) {
  const int w = 80, h = 50, samples = 16, pixels = w * h;
  std::mt19937 rng(12);
  std::normal_distribution<double> offset(0.0, 0.1);
  std::vector<double> replicateOffset(2 * pixels);
  for (double& o : replicateOffset) o = offset(rng);
  const float value = 2.f;
  Film film(w, h);
  Feed(film, samples, [&](int i, int s) {
    const int replicate = s & 1, stratum = (s >> 1) & 1;
    return RGB((float)(value + replicateOffset[2 * i + replicate] + (stratum ? 1.0 : -1.0)));
  });
  double squaredError = 0, spread = 0;
  for (int i = 0; i < pixels; ++i) {
    const double e = film.Mean(i % w, i / w).g - value;
    squaredError += e * e / pixels;
    spread += film.VarianceOfMean(i % w, i / w).g / pixels;
  }
  const NoiseEstimate noise = film.Noise();
  const double estimate = noise.rmsStandardError * noise.rmsStandardError, trueVar = 0.01 / 2;
  RecordProperty("estimate_over_true", std::to_string(estimate / trueVar));
  EXPECT_NEAR(estimate / trueVar, 1.0, 5 * 0.022);
  EXPECT_NEAR(estimate / squaredError, 1.0, 5 * 0.022 * std::sqrt(2.0));
  EXPECT_GT(spread, 8 * trueVar) << "the samples' spread overstates this error; else the test shows nothing";
}

// Too few samples for two replicates: no estimate yet (0), not a wrong one.
TEST(FilmNoise, NeedsASampleInEachReplicate) {
  Film film(3, 2);
  Feed(film, 1, [](int i, int) { return RGB(1.f + i); });
  EXPECT_EQ(0.0, film.Noise().rmsStandardError);
  film.View().AddSample(0, 0, RGB(3.f), 1.f, 2);  // a second sample in one pixel only
  film.SetPixelSamples({2, 1, 1, 1, 1, 1});
  // Pixel 0: m0 = 1, m1 = 3, (m0 - m1)^2 / 4 = 1, over 6 pixels.
  EXPECT_NEAR(std::sqrt(1.0 / 6), film.Noise().rmsStandardError, 1e-6);
}

TEST(FilmMoments, TwoSeedsCombinedAgreeWithASerialRenderOfTwiceTheSamples) {
  Scene scene =
      test::MakeMediumScene(test::MakeVolume(12, 12, 12, [](int i, int j, int k) { return (i * j + k) % 5 / 4.f; }),
                            1.f, RGB(0.9f, 0.7f, 0.5f), 0.3f);
  scene.environment = EnvironmentMap::DefaultSky();
  // Independent samples: the z-scores below take each pixel's sample
  // variance for its spread, which stratified (Sobol') samples overstate
  // (here about threefold: mean z^2 0.34).
  scene.render.integrator.sampler = PixelSampler::Independent;
  auto render = [&](uint64_t seed, int samples) {
    scene.render.integrator.seed = seed;
    const SceneView view = scene.Build();
    Film film(24, 20);
    CpuRenderer(2).Render(view, film, samples);
    return film;
  };
  const Film rank0 = render(1, 16), rank1 = render(2, 16), serial = render(99, 32);
  const Film combined = Film::FromMoments(24, 20, 32, Sum(rank0.Moments(), rank1.Moments()));
  // Mean z^2 over ~1,400 pixel channels: 1 +- 0.04 for independent
  // estimates of one image. The bounds are wide of that noise and far
  // below what a dropped half (the variance of 16 samples claimed as 32's)
  // or a biased stream gives; the third check shows the test can fail.
  const double z2 = MeanSquaredZScore(combined, serial);
  RecordProperty("mean_z2", std::to_string(z2));
  EXPECT_GT(z2, 0.7);
  EXPECT_LT(z2, 1.4);
  // The noise of the combined film is the serial render's: 480 pixels, one
  // degree of freedom each, so each film's squared noise is good to about
  // sqrt(2 / 480) = 6.5 %, the ratio of the two noises to about 5 %.
  const double noiseRatio = combined.Noise().relative / serial.Noise().relative;
  RecordProperty("noise_ratio", std::to_string(noiseRatio));
  EXPECT_GT(noiseRatio, 0.8);
  EXPECT_LT(noiseRatio, 1.25);
  // One rank's samples counted twice (its variance halved): about 1.5.
  const Film claimed = Film::FromMoments(24, 20, 32, Sum(rank0.Moments(), rank0.Moments()));
  EXPECT_GT(MeanSquaredZScore(claimed, serial), 1.3);
  scene.materials[0].base[1] = 0.2f;  // a biased stream: another red albedo
  const Film biased = render(3, 16);
  const Film mixed = Film::FromMoments(24, 20, 32, Sum(rank0.Moments(), biased.Moments()));
  EXPECT_GT(MeanSquaredZScore(mixed, serial), 1.4);
}

}  // namespace
}  // namespace mmrtm
