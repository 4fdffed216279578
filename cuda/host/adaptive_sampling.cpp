#include "adaptive_sampling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mmrtm {

std::vector<float> AdaptiveSampleWeights(const Film& pilot) {
  if (pilot.Adaptive() || pilot.Samples() < 2)
    throw std::invalid_argument("AdaptiveSampleWeights: the pilot must be uniform with at least 2 samples, has " +
                                std::to_string(pilot.Samples()));
  const int w = pilot.Width(), h = pilot.Height();
  const double n = pilot.Samples();
  // Luminance standard deviation of one sample, bounded by the channels'
  // (as Film::Noise): sqrt(n) times the standard error of the mean.
  std::vector<float> sigma((size_t)w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const RGB v = pilot.VarianceOfMean(x, y);
      auto sd = [n](float var) { return std::sqrt(std::max(0.0, (double)var) * n); };
      sigma[(size_t)y * w + x] = (float)(0.2126 * sd(v.r) + 0.7152 * sd(v.g) + 0.0722 * sd(v.b));
    }
  std::vector<float> weights((size_t)w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sumSigma = 0, sumCost = 0;
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          sumSigma += sigma[(size_t)ny * w + nx];
          sumCost += pilot.Work(nx, ny) / n;
          ++count;
        }
      // sigma / sqrt(cost): the best split when pixels cost differently
      // (minimise sum sigma^2 / n_i subject to sum n_i c_i fixed).
      const double cost = pilot.TracksWork() ? std::max(1.0, sumCost / std::max(count, 1)) : 1.0;
      weights[(size_t)y * w + x] = count ? (float)(sumSigma / count / std::sqrt(cost)) : 0.f;
    }
  return weights;
}

std::vector<uint32_t> AdaptiveSampleCounts(const Film& film, const std::vector<float>& weights, double meanSamples,
                                           uint32_t maxPerPixel) {
  const int w = film.Width(), h = film.Height();
  const size_t pixels = (size_t)w * h;
  if (weights.size() != pixels)
    throw std::invalid_argument("AdaptiveSampleCounts: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(pixels) + " pixels");
  std::vector<uint32_t> current(pixels);
  double weightSum = 0;
  for (size_t i = 0; i < pixels; ++i) {
    current[i] = film.PixelSamples((int)(i % w), (int)(i / w));
    weightSum += weights[i];
  }
  const double cap = std::max<double>(maxPerPixel, 1);
  auto countAt = [&](size_t i, double scale) {
    const double share = weightSum > 0 ? scale * weights[i] : scale;
    return std::max<double>(current[i], std::min(cap, std::floor(share + 0.5)));
  };
  auto mean = [&](double scale) {
    double sum = 0;
    for (size_t i = 0; i < pixels; ++i) sum += countAt(i, scale);
    return sum / (double)pixels;
  };
  // The mean count grows with the scale: bisect for the one that gives
  // meanSamples (or the cap everywhere, if that is less).
  double lo = 0, hi = 1;
  while (mean(hi) < meanSamples && hi < 1e30 && mean(hi) < cap) hi *= 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mean(mid) < meanSamples ? lo : hi) = mid;
  }
  std::vector<uint32_t> counts(pixels);
  for (size_t i = 0; i < pixels; ++i) counts[i] = (uint32_t)countAt(i, hi);
  return counts;
}

}  // namespace mmrtm
