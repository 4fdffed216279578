#include "denoised_display.h"

#include "mmrtm/planted_defect.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mmrtm {

std::optional<DenoisingMode> ParseDenoisingMode(const std::string& name) {
  if (name == "off") return DenoisingMode::Off;
  if (name == "auto") return DenoisingMode::Auto;
  if (name == "always") return DenoisingMode::Always;
  return std::nullopt;
}

const char* DenoisingModeName(DenoisingMode mode) {
  switch (mode) {
    case DenoisingMode::Off:
      return "off";
    case DenoisingMode::Auto:
      return "auto";
    case DenoisingMode::Always:
      return "always";
  }
  return "off";
}

FilmSnapshot SnapshotFilm(const Film& film, uint64_t generation) {
  FilmSnapshot s;
  s.generation = generation;
  s.samples = film.Samples();
  s.color = film.Linear();
  s.alpha.resize((size_t)film.Width() * film.Height());
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) s.alpha[(size_t)y * film.Width() + x] = film.Alpha(x, y);
  s.tracksInputs = film.TracksDenoiserInputs();
  s.hasHalves = s.tracksInputs && film.Samples() >= 2;
  if (s.hasHalves) s.halves = film.DenoiserImages();
  return s;
}

namespace {

// The mean over pixels and channels of (a - b)^2.
double MeanSquaredDifference(const RGBImage& a, const RGBImage& b) {
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = (double)a.pixels[i][c] - b.pixels[i][c];
      sum += d * d;
    }
  return a.pixels.empty() ? 0.0 : sum / (3.0 * a.pixels.size());
}

// The mean of per-pixel terms plus two standard errors (over pixels), at
// least 0: an estimate of a denoised image's error is a difference of two
// terms that, at a few samples, are large and close, and alone it may even
// come out below 0; the bound keeps Auto from taking that for a perfect
// image.
class ErrorBound {
 public:
  void Add(double t) {
    sum_ += t;
    sumSquares_ += t * t;
    ++n_;
  }
  double Bound() const {
    if (n_ < 2) return 0.0;
    const double mean = sum_ / n_, variance = std::max(0.0, (sumSquares_ - sum_ * mean) / (n_ - 1));
    return std::max(0.0, mean + 2.0 * std::sqrt(variance / n_));
  }

 private:
  double sum_ = 0, sumSquares_ = 0;
  int64_t n_ = 0;
};

// The denoised half's error, MSE(D(A)) = E (D(A) - B)^2 - Var B, bounded.
double DenoisedHalfErrorBound(const RGBImage& denoisedA, const RGBImage& a, const RGBImage& b, double n0, double n) {
  ErrorBound bound;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    double t = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = (double)denoisedA.pixels[i][c] - b.pixels[i][c], h = (double)a.pixels[i][c] - b.pixels[i][c];
      t += (d * d - h * h * (Planted(Defect::DenoiseVariance) ? 1.0 : n0 / n)) / 3.0;
    }
    bound.Add(t);
  }
  return bound.Bound();
}

}  // namespace

std::optional<DenoisedFilm> DenoiseSnapshot(const FilmSnapshot& s, bool estimate, bool useGuides,
                                            const DenoiseFunction& denoise, const std::atomic<bool>* cancel) {
  const auto start = std::chrono::steady_clock::now();
  DenoisedFilm out;
  out.generation = s.generation;
  out.samples = s.samples;
  if (s.hasHalves) {
    out.filmMean = s.color;
    out.filmEvenMean = s.halves.color[0];
  } else if (s.samples == 1 && s.tracksInputs) {
    out.filmMean = out.filmEvenMean = s.color;  // its one sample is its even half
  }
  // The coverage is denoised as the colour is (a grey image): at a few
  // samples the coverage of translucent matter is as noisy as its colour,
  // and the background would show through it in specks.
  RGBImage coverage{s.color.width, s.color.height, std::vector<RGB>(s.alpha.size())};
  for (size_t i = 0; i < s.alpha.size(); ++i) coverage.pixels[i] = RGB(s.alpha[i]);
  const bool guided = useGuides && s.hasHalves;
  std::vector<RGBImage> denoised = denoise({&s.color, &coverage}, guided ? &s.halves.albedoWhole : nullptr,
                                           guided ? &s.halves.normalWhole : nullptr, cancel);
  if (denoised.size() != 2) return std::nullopt;
  out.image = std::move(denoised[0]);
  out.alpha.resize(s.alpha.size());
  for (size_t i = 0; i < s.alpha.size(); ++i) out.alpha[i] = std::clamp(denoised[1].pixels[i].g, 0.f, 1.f);
  if (estimate && s.hasHalves) {
    // D(A) against B (the header's reasoning), A denoised with its own
    // guides: the whole film's know where B's camera rays first collided,
    // which made the estimate 5-8 % low on the bonsai
    // (Documentation/denoising.md). The halves' variances from their
    // difference: E (A - B)^2 = Var A + Var B, each going as 1 / its
    // samples.
    const FilmHalves& h = s.halves;
    const std::vector<RGBImage> half =
        denoise({&h.color[0]}, guided ? &h.albedo[0] : nullptr, guided ? &h.normal[0] : nullptr, cancel);
    if (half.size() != 1) return std::nullopt;
    const double n0 = h.samples[0], n1 = h.samples[1], n = n0 + n1;
    DenoiseEstimate e;
    e.samples = s.samples;
    e.denoised = DenoisedHalfErrorBound(half[0], h.color[0], h.color[1], n0, n);
    e.film = MeanSquaredDifference(h.color[0], h.color[1]) * n0 * n1 / (n * n);
    double sum = 0;
    for (const RGB& p : s.color.pixels) sum += (double)p.r + p.g + p.b;
    e.meanValue = s.color.pixels.empty() ? 0.0 : sum / (3.0 * s.color.pixels.size());
    out.estimate = e;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

DenoiseFunction OidnDenoise(Denoiser& denoiser) {
  return [&denoiser](const std::vector<const RGBImage*>& colors, const RGBImage* albedo, const RGBImage* normal,
                     const std::atomic<bool>* cancel) {
    RGBImage cleanAlbedo, cleanNormal;
    if (albedo) {
      cleanAlbedo = denoiser.DenoiseGuide(*albedo, Denoiser::Guide::Albedo, cancel);
      if (normal) cleanNormal = denoiser.DenoiseGuide(*normal, Denoiser::Guide::Normal, cancel);
      if (cleanAlbedo.pixels.empty() || (normal && cleanNormal.pixels.empty())) return std::vector<RGBImage>{};
    }
    std::vector<RGBImage> out;
    for (const RGBImage* color : colors) {
      out.push_back(albedo ? denoiser.Denoise(*color, &cleanAlbedo, normal ? &cleanNormal : nullptr, true, cancel)
                           : denoiser.Denoise(*color, nullptr, nullptr, false, cancel));
      if (out.back().pixels.empty()) return std::vector<RGBImage>{};
    }
    return out;
  };
}

void DenoisedDisplay::Recheck(const Film& film, uint64_t generation) {
  const uint32_t n = film.Samples();
  if (mode_ != DenoisingMode::Auto || !last_ || generation != generation_ || settledOnFilm_ || film.Adaptive() ||
      !film.TracksDenoiserInputs() || last_->filmEvenMean.pixels.empty() || last_->filmMean.width != film.Width() ||
      last_->filmMean.height != film.Height())
    return;
  const uint32_t m = last_->samples, n0 = (n + 1) / 2, m0 = (m + 1) / 2;
  if (n <= m || n0 <= m0 || n - n0 <= m - m0) return;  // new samples in both halves
  // Each time the new samples have doubled: a check of a few new samples is
  // loose (their noise is most of the difference), and the bound kept is
  // the tightest so far, which many checks in a row would bias low.
  if (rechecked_ && n - m < 2 * (rechecked_ - m)) return;
  rechecked_ = n;
  // The samples since the denoise: their sum is n F_n - m F_m (even ones:
  // n0 A_n - m0 A_m), their mean F' an unbiased estimate independent of
  // the denoised image D, and E (D - F')^2 = MSE(D) + Var F', Var F' from
  // their own halves' difference. The film's error from its halves.
  const double k = n - m, k0 = n0 - m0, k1 = k - k0, n1 = n - n0;
  const RGBImage& image = last_->image;
  ErrorBound denoised;
  double filmError = 0, sum = 0;
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      const size_t i = (size_t)y * film.Width() + x;
      const RGB f = film.Mean(x, y), a = film.EvenMean(x, y), fm = last_->filmMean.pixels[i],
                am = last_->filmEvenMean.pixels[i];
      double t = 0;
      for (int c = 0; c < 3; ++c) {
        const double all = (double)n * f[c] - (double)m * fm[c], even = (double)n0 * a[c] - (double)m0 * am[c];
        const double mean = all / k, evenMean = even / k0, oddMean = (all - even) / k1;
        const double d = (double)image.pixels[i][c] - mean, h = evenMean - oddMean;
        t += (d * d - h * h * k0 * k1 / (k * k)) / 3.0;
        const double b = ((double)n * f[c] - (double)n0 * a[c]) / n1, filmH = a[c] - b;
        filmError += filmH * filmH * n0 * n1 / ((double)n * n) / 3.0;
        sum += f[c] / 3.0;
      }
      denoised.Add(t);
    }
  const double pixels = (double)film.Width() * film.Height();
  DenoiseEstimate e;
  e.samples = n;
  // Both are bounds of this image's error (an earlier one by the denoiser's
  // error not growing with samples): the tighter holds.
  e.denoised = estimate_ ? std::min(estimate_->denoised, denoised.Bound()) : denoised.Bound();
  e.film = filmError / pixels;
  e.meanValue = sum / pixels;
  estimate_ = e;
}

bool DenoisedDisplay::Due(uint64_t generation, uint32_t samples, bool accumulating, Clock::time_point now) const {
  if (mode_ == DenoisingMode::Off || busy_ || samples == 0 || !unavailable_.empty()) return false;
  if (generation != generation_ || !last_) return true;  // a new accumulation: at once
  if (samples <= last_->samples) return false;
  if (mode_ == DenoisingMode::Auto && settledOnFilm_) return false;
  return !accumulating || std::chrono::duration<double>(now - finished_).count() >= 3.0 * lastSeconds_;
}

bool DenoisedDisplay::WantsEstimate(uint64_t generation, uint32_t samples) const {
  if (mode_ != DenoisingMode::Auto || samples < 2) return false;
  return generation != generation_ || !estimate_ || !estimate_->DenoisedCloserAt(samples);
}

void DenoisedDisplay::Finished(std::optional<DenoisedFilm> result, Clock::time_point now) {
  busy_ = false;
  finished_ = now;
  lastSeconds_ = std::chrono::duration<double>(now - started_).count();
  seconds_ += lastSeconds_;
  if (!result) return;
  ++denoises_;
  if (result->generation != generation_) {
    generation_ = result->generation;
    estimate_.reset();
    settledOnFilm_ = false;
  }
  if (result->estimate) {
    estimate_ = result->estimate;
    settledOnFilm_ = !estimate_->DenoisedCloserAt(estimate_->samples);
  }
  last_ = std::move(result);
  rechecked_ = 0;
}

const DenoisedFilm* DenoisedDisplay::Shown(uint64_t generation, uint32_t samples) const {
  if (mode_ == DenoisingMode::Off || !last_ || generation != generation_ || samples == 0) return nullptr;
  if (mode_ == DenoisingMode::Always) return &*last_;
  if (settledOnFilm_) return nullptr;
  return !estimate_ || estimate_->DenoisedCloserAt(samples) ? &*last_ : nullptr;
}

const DenoiseEstimate* DenoisedDisplay::Estimate(uint64_t generation) const {
  return generation == generation_ && estimate_ ? &*estimate_ : nullptr;
}

std::string DenoisedDisplay::Status(uint64_t generation, uint32_t samples, double relativeNoise) const {
  char text[160];
  const DenoisedFilm* shown = Shown(generation, samples);
  if (shown) {
    std::snprintf(text, sizeof text, "denoised, %u sample%s", shown->samples, shown->samples == 1 ? "" : "s");
    return text;
  }
  if (samples == 0) return "no samples yet";
  std::snprintf(text, sizeof text, "unbiased, %u sample%s", samples, samples == 1 ? "" : "s");
  std::string status = text;
  if (samples >= 2) {
    std::snprintf(text, sizeof text, ", noise %.1f %%", 100.0 * relativeNoise);
    status += text;
  }
  if (mode_ != DenoisingMode::Off && !unavailable_.empty()) status += " (not denoised: " + unavailable_ + ")";
  return status;
}

}  // namespace mmrtm
