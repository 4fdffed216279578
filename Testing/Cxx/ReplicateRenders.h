// Image estimates for ImageAgreement.h from the tracer: independent
// replicate renders (other seeds: independently scrambled Sobol' nets, or
// independent streams), or one film of independent samples.
#pragma once

#include <functional>
#include <stdexcept>
#include <vector>

#include "ImageAgreement.h"
#include "cpu_renderer.h"

namespace mmrtm::test {

// The film's mean radiance, RGB per pixel, row 0 at the top.
inline std::vector<float> FilmPixels(const Film& film) {
  std::vector<float> out;
  out.reserve((size_t)film.Width() * film.Height() * 3);
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      const RGB c = film.Mean(x, y);
      out.insert(out.end(), {c.r, c.g, c.b});
    }
  return out;
}

// `replicates` films made by render(seed) for seeds firstSeed, firstSeed + 1,
// ...; `combined`, when given, becomes the film of all their samples (for
// an image to look at). Uniform films only when `combined` is asked for.
inline ImageEstimate EstimateFromReplicates(int replicates, uint64_t firstSeed,
                                            const std::function<Film(uint64_t seed)>& render,
                                            Film* combined = nullptr) {
  std::vector<std::vector<float>> images;
  std::vector<double> moments;
  uint32_t samples = 0;
  int width = 0, height = 0;
  for (int r = 0; r < replicates; ++r) {
    const Film film = render(firstSeed + (uint64_t)r);
    width = film.Width();
    height = film.Height();
    images.push_back(FilmPixels(film));
    if (combined) {
      const std::vector<double> m = film.Moments();
      moments.resize(m.size(), 0.0);
      for (size_t i = 0; i < m.size(); ++i) moments[i] += m[i];
      samples += film.Samples();
    }
  }
  if (combined) *combined = Film::FromMoments(width, height, samples, moments);
  return FromReplicates(images, width, height);
}

// `replicates` renders of `view` with `spp` samples each, seeds firstSeed,
// firstSeed + 1, ...; the work of all of them is added to `counters`.
inline ImageEstimate RenderReplicates(SceneView view, int replicates, int spp, uint64_t firstSeed,
                                      TraceCounters* counters = nullptr, Film* combined = nullptr, int threads = 2) {
  return EstimateFromReplicates(
      replicates, firstSeed,
      [&](uint64_t seed) {
        view.settings.seed = seed;
        Film film(view.camera.width, view.camera.height);
        CpuRenderer(threads).Render(view, film, spp, counters);
        return film;
      },
      combined);
}

// One film whose samples are all independent (PixelSampler::Independent):
// its samples' spread is its error.
inline ImageEstimate FromIndependentSamples(const Film& film) {
  if (film.Adaptive() || film.Samples() < 2)
    throw std::invalid_argument("FromIndependentSamples: a uniform film of 2 samples or more");
  ImageEstimate e;
  e.width = film.Width();
  e.height = film.Height();
  e.degreesOfFreedom = (double)film.Samples() - 1;
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      const RGB m = film.Mean(x, y), v = film.VarianceOfMean(x, y);
      for (int c = 0; c < 3; ++c) {
        e.mean.push_back(m[c]);
        e.variance.push_back(v[c]);
      }
    }
  return e;
}

}  // namespace mmrtm::test
