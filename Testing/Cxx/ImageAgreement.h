// Whether two Monte Carlo estimates of one image agree, with a stated power.
//
// An ImageEstimate holds, per pixel and channel, a mean and the variance of
// that mean. The variance must be what independent replicates say: the
// spread of R independent renders' means (FromReplicates: independently
// scrambled Sobol' replicates, i.e. other seeds), or the samples' own spread
// where every sample is independent (--sampler independent). A Sobol'
// film's own per-pixel variance overstates its error about threefold and
// must not be used here.
//
// Compare() runs two tests and fails if either does:
//  - the global test: per channel, the mean over covered pixels (those with
//    noise in either image) of a - b, in standard errors. Under agreement
//    each is N(0, 1) (a mean over thousands of independent pixels);
//  - the block test: on block x block pixel blocks, the mean over blocks
//    of z^2 = (a - b)^2 / (var_a + var_b), averaged over the channels. Each
//    channel's z^2 is F(1, nu) distributed, nu from the degrees of freedom
//    of the two block variances (Welch-Satterthwaite), which come from the
//    replicates' block means (or else the pixels' variances); a block's
//    channels move together (one path carries all three), so the block's
//    term has that mean and at most that variance; the limit is the
//    Wilson-Hilferty quantile of the sum over blocks.
// The false-failure probability of the two together is `falseFailure`
// (default 1e-4), split between them (Bonferroni). Blocks without noise
// (the environment seen directly) must agree to float precision.
//
// Power: the smallest relative change of a channel's covered-pixel mean
// that the global test catches with probability 1 - falseFailure, i.e.
// (z_limit + z_power) standard errors of that mean. Tests assert it (the
// aim: 2 %) and show it by comparing against a scaled copy (Scaled()).
//
// No dependencies beyond the standard library: the VTK image tests use it
// on the mapper's accumulated images too.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace mmrtm::test {

// The standard normal quantile (Acklam's rational approximation refined by
// one Halley step: about 1e-15 relative).
inline double NormalQuantile(double p) {
  if (!(p > 0 && p < 1)) throw std::invalid_argument("NormalQuantile: p must lie in (0, 1)");
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x;
  if (p < 0.02425) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p > 1 - 0.02425) {
    const double q = std::sqrt(-2 * std::log(1 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2 * M_PI) * std::exp(x * x / 2);
  return x - u / (1 + x * u / 2);
}

// Per pixel and channel, row-major: the mean and the variance of the mean,
// and the degrees of freedom of each variance (replicates - 1, or samples - 1).
// An estimate made from replicates keeps them: the block test takes a
// block's variance from its replicates' block means, which are close to
// normal, where a sum of few-sample pixel variances of heavy-tailed path
// samples is not chi-square and would make z^2 larger than F(1, nu) says
// (measured: mean block z^2 1.10-1.14 for 8 replicates a side, where F's
// mean is 1.02).
struct ImageEstimate {
  int width = 0, height = 0, channels = 3;
  std::vector<double> mean, variance;
  double degreesOfFreedom = 0;
  std::vector<std::vector<float>> replicates;  // each width x height x channels, or none

  size_t Values() const { return (size_t)width * height * channels; }
};

// From R >= 2 independent replicate images of `width x height x channels`
// floats each (row-major, channels interleaved; `stride` floats a pixel when
// the images carry more, e.g. alpha): their mean, and per value the variance
// of that mean, s^2 / R.
template <class Image>
ImageEstimate FromReplicates(const std::vector<Image>& replicates, int width, int height, int channels = 3,
                             int stride = 0) {
  const size_t R = replicates.size();
  if (R < 2) throw std::invalid_argument("FromReplicates: at least two replicates");
  if (stride == 0) stride = channels;
  ImageEstimate e;
  e.width = width;
  e.height = height;
  e.channels = channels;
  e.degreesOfFreedom = (double)R - 1;
  e.mean.assign(e.Values(), 0.0);
  e.variance.assign(e.Values(), 0.0);
  e.replicates.assign(R, std::vector<float>(e.Values()));
  for (size_t p = 0; p < (size_t)width * height; ++p)
    for (int c = 0; c < channels; ++c) {
      double sum = 0, sum2 = 0;
      for (size_t r = 0; r < R; ++r) {
        sum += replicates[r][p * stride + c];
        e.replicates[r][p * channels + c] = (float)replicates[r][p * stride + c];
      }
      const double m = sum / R;
      for (const Image& r : replicates) sum2 += (r[p * stride + c] - m) * (r[p * stride + c] - m);
      e.mean[p * channels + c] = m;
      e.variance[p * channels + c] = sum2 / (R - 1) / R;
    }
  return e;
}

// The estimate times `factor`: a planted bias, to show a comparison's power.
inline ImageEstimate Scaled(ImageEstimate e, double factor) {
  for (double& m : e.mean) m *= factor;
  for (double& v : e.variance) v *= factor * factor;
  for (auto& r : e.replicates)
    for (float& v : r) v = (float)(v * factor);
  return e;
}

// Before comparing a test image with a reference of the same estimator and
// many more samples. Where a pixel's light comes from rare paths (wisps of
// low opacity, the rims of labels), a few replicates may see none of them:
// their spread is then 0, and a block of such pixels, whose reference has
// seen those paths, counts as dozens of standard errors off (the
// t-statistic of a rare event). So the test's variance of a value is at
// least `fraction` of what the reference's variance says for the test's
// sample count, and the block test sums these pixel variances rather than
// taking the replicates' block means (which see the same nothing).
// Measured on the VTK regression images (16 sets of 8 x 16 samples a case,
// Testing/VTK): without the floor the labels case failed 15 of 16 sets
// (8 of 16 with the replicates' block means), with it none of 80.
inline void FloorVarianceByReference(ImageEstimate& test, const ImageEstimate& reference, double testSamples,
                                     double referenceSamples, double fraction = 0.5) {
  if (test.variance.size() != reference.variance.size())
    throw std::invalid_argument("FloorVarianceByReference: estimates of different sizes");
  const double scale = fraction * referenceSamples / testSamples;
  for (size_t i = 0; i < test.variance.size(); ++i)
    test.variance[i] = std::max(test.variance[i], scale * reference.variance[i]);
  test.replicates.clear();
}

// The variance of the mean of one channel of a block, and its degrees of
// freedom: from the replicates' block means where the estimate has them,
// else the pixels' variances summed (Welch-Satterthwaite; 1e9: known).
inline void BlockVariance(const ImageEstimate& e, int bx, int by, int B, int c, double* variance, double* df) {
  const int C = e.channels, W = e.width;
  const double n = (double)B * B;
  if (e.replicates.size() >= 2) {
    const size_t R = e.replicates.size();
    std::vector<double> means(R, 0.0);
    for (size_t r = 0; r < R; ++r)
      for (int y = by; y < by + B; ++y)
        for (int x = bx; x < bx + B; ++x) means[r] += e.replicates[r][((size_t)y * W + x) * C + c] / n;
    double m = 0, ss = 0;
    for (double v : means) m += v / R;
    for (double v : means) ss += (v - m) * (v - m);
    *variance = ss / (R - 1) / R;
    *df = (double)R - 1;
    return;
  }
  double sum = 0, sumSquares = 0;
  for (int y = by; y < by + B; ++y)
    for (int x = bx; x < bx + B; ++x) {
      const double v = e.variance[((size_t)y * W + x) * C + c];
      sum += v;
      sumSquares += v * v;
    }
  *variance = sum / (n * n);
  *df = e.degreesOfFreedom > 0 && sumSquares > 0 ? sum * sum / (sumSquares / e.degreesOfFreedom) : 1e9;
}

struct AgreementOptions {
  int block = 4;
  double falseFailure = 1e-4;  // probability that two estimates of one image fail
};

struct Agreement {
  // Global test, per channel: (mean_a - mean_b) over covered pixels, in
  // standard errors, and that standard error relative to b's mean there.
  std::vector<double> globalZ, relativeStandardError;
  double globalLimit = 0;
  // The smallest relative change of any one channel's covered-pixel mean
  // that fails with probability 1 - falseFailure.
  double power = 0;
  size_t coveredPixels = 0;
  // Block test.
  double blockMeanZ2 = 0, blockLimit = 0;
  size_t blockTerms = 0;
  size_t noiselessBlocksThatDiffer = 0;
  // The largest single block |z| (informative).
  double maxBlockZ = 0;

  bool GlobalAgrees() const {
    for (double z : globalZ)
      if (!(std::fabs(z) <= globalLimit)) return false;
    return true;
  }
  bool BlocksAgree() const { return blockMeanZ2 <= blockLimit && noiselessBlocksThatDiffer == 0; }
  bool Agrees() const { return GlobalAgrees() && BlocksAgree(); }

  std::string Describe() const {
    std::string s = "global z";
    char buf[256];
    for (double z : globalZ) {
      std::snprintf(buf, sizeof buf, " %+.2f", z);
      s += buf;
    }
    std::snprintf(buf, sizeof buf,
                  " (limit %.2f, %zu covered pixels, power %.2f %%); block mean z^2 %.3f (limit %.3f, %zu terms, "
                  "max |z| %.1f); noiseless blocks that differ: %zu",
                  globalLimit, coveredPixels, 100 * power, blockMeanZ2, blockLimit, blockTerms, maxBlockZ,
                  noiselessBlocksThatDiffer);
    return s + buf;
  }
};

inline Agreement Compare(const ImageEstimate& a, const ImageEstimate& b, const AgreementOptions& options = {}) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels || a.mean.size() != a.Values() ||
      b.mean.size() != b.Values())
    throw std::invalid_argument("Compare: estimates of different sizes");
  const int C = a.channels, W = a.width, H = a.height;
  Agreement r;
  // Half the false-failure budget to each test; the global one's spread
  // over the channels, two-sided.
  const double alpha = options.falseFailure / 2;
  r.globalLimit = NormalQuantile(1 - alpha / (2 * C));
  const double zPower = NormalQuantile(1 - options.falseFailure);

  // A value is noisy where its variance is above float rounding of its size.
  auto noiseless = [](double var, double value) { return var <= std::pow(1e-7 * (std::fabs(value) + 1e-3), 2); };

  // Global test over covered pixels.
  std::vector<char> covered((size_t)W * H, 0);
  for (size_t p = 0; p < covered.size(); ++p)
    for (int c = 0; c < C; ++c) {
      const size_t i = p * C + c;
      if (!noiseless(a.variance[i] + b.variance[i], b.mean[i])) covered[p] = 1;
    }
  r.coveredPixels = (size_t)std::count(covered.begin(), covered.end(), 1);
  for (int c = 0; c < C; ++c) {
    double diff = 0, var = 0, level = 0;
    for (size_t p = 0; p < covered.size(); ++p) {
      if (!covered[p]) continue;
      const size_t i = p * C + c;
      diff += a.mean[i] - b.mean[i];
      var += a.variance[i] + b.variance[i];
      level += b.mean[i];
    }
    r.globalZ.push_back(var > 0 ? diff / std::sqrt(var) : (diff == 0 ? 0.0 : INFINITY));
    const double rse = level > 0 ? std::sqrt(var) / level : INFINITY;
    r.relativeStandardError.push_back(rse);
    r.power = std::max(r.power, (r.globalLimit + zPower) * rse);
  }

  // Block test. The channels of a pixel come from the same paths and move
  // together, so a block's channels count as one term: the mean of their
  // z^2, whose variance is at most that of one channel's (the bound is
  // reached when they move as one, as they nearly do in renders).
  const int B = options.block;
  double sumMean = 0, sumVar = 0, sumZ2 = 0;
  for (int by = 0; by + B <= H; by += B)
    for (int bx = 0; bx + B <= W; bx += B) {
      double termZ2 = 0, termMean = 0, termSd = 0;
      int noisyChannels = 0;
      for (int c = 0; c < C; ++c) {
        double ma = 0, mb = 0;
        for (int y = by; y < by + B; ++y)
          for (int x = bx; x < bx + B; ++x) {
            const size_t i = ((size_t)y * W + x) * C + c;
            ma += a.mean[i];
            mb += b.mean[i];
          }
        const double n = (double)B * B;
        ma /= n;
        mb /= n;
        double varA, dfA, varB, dfB;
        BlockVariance(a, bx, by, B, c, &varA, &dfA);
        BlockVariance(b, bx, by, B, c, &varB, &dfB);
        const double var = varA + varB;
        if (noiseless(var, mb)) {
          r.noiselessBlocksThatDiffer += std::fabs(ma - mb) > 1e-5 * std::fabs(mb) + 1e-7;
          continue;
        }
        const double z2 = (ma - mb) * (ma - mb) / var;
        r.maxBlockZ = std::max(r.maxBlockZ, std::sqrt(z2));
        // Welch-Satterthwaite; z^2 ~ F(1, nu): mean nu / (nu - 2), variance
        // 2 nu^2 (nu - 1) / ((nu - 2)^2 (nu - 4)).
        const double nu = std::max(5.0, var * var / (varA * varA / dfA + varB * varB / dfB));
        termZ2 += z2;
        termMean += nu / (nu - 2);
        termSd += std::sqrt(2 * nu * nu * (nu - 1) / ((nu - 2) * (nu - 2) * (nu - 4)));
        ++noisyChannels;
      }
      if (noisyChannels == 0) continue;
      sumZ2 += termZ2 / noisyChannels;
      sumMean += termMean / noisyChannels;
      sumVar += (termSd / noisyChannels) * (termSd / noisyChannels);
      ++r.blockTerms;
    }
  if (r.blockTerms > 0) {
    const double K = (double)r.blockTerms, z = NormalQuantile(1 - alpha);
    // Wilson-Hilferty: chi^2_K / K below (1 - 2/(9K) + z sqrt(2/(9K)))^3;
    // its excess over 1 scaled to the terms' spread and shifted to their mean.
    const double wh = std::pow(1 - 2 / (9 * K) + z * std::sqrt(2 / (9 * K)), 3);
    r.blockMeanZ2 = sumZ2 / K;
    r.blockLimit = sumMean / K + (wh - 1) * std::sqrt(sumVar / (2 * K));
  }
  return r;
}

}  // namespace mmrtm::test
