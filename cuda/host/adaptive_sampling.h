// Adaptive sampling: more samples where a pixel's estimate is noisier.
//
// For an image error measured as the RMS over pixels of their standard
// errors (Film::Noise, the relative RMSE against a reference), the best
// split of a time budget gives pixel i samples in proportion to
// sigma_i / sqrt(c_i), its per-sample standard deviation over the square
// root of its cost per sample (minimise sum sigma_i^2 / n_i with sum n_i c_i
// fixed). Both are estimated from a uniform pilot pass, the cost from the
// pixel's work (TraceCounters::Work) when the pilot film tracks it.
//
// Unbiased by construction: a pixel's count must not depend on its own
// samples (stopping a pixel when its own estimate happens to look smooth
// would bias it), so its weight comes from its eight neighbours in the
// pilot, never from itself. Every pixel has its own random stream
// (PixelSampleRNG), so its samples are independent of its count, and its
// mean over all of them (pilot included) is an unbiased estimate. The
// neighbourhood also smooths the pilot's few-sample estimates. Host-only.
#pragma once

#include <cstdint>
#include <vector>

#include "film.h"

namespace mmrtm {

// Per-pixel weights (row-major) from a uniformly sampled pilot film with at
// least 2 samples: for each pixel the mean over its neighbours (8, fewer on
// the border) of their luminance standard deviation per sample (bounded as
// Film::Noise bounds it), divided by the square root of their mean work per
// sample (at least 1) when the film tracks work. Throws
// std::invalid_argument for an adaptive film or one of fewer than 2 samples.
std::vector<float> AdaptiveSampleWeights(const Film& pilot);

// Per-pixel sample counts whose mean is about `meanSamples`, each pixel's in
// proportion to its weight but never below its count in `film` nor above
// `maxPerPixel`. Where every weight is 0 (a noiseless pilot) the budget is
// spread uniformly.
std::vector<uint32_t> AdaptiveSampleCounts(const Film& film, const std::vector<float>& weights, double meanSamples,
                                           uint32_t maxPerPixel);

}  // namespace mmrtm
