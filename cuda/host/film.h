// The host film: owns the accumulation buffers behind a FilmView, and turns
// them into images and noise figures. Host-only.
#pragma once

#include <cstdint>
#include <vector>

#include "image_io.h"
#include "mmrtm/film_view.h"
#include "mmrtm/tonemap.h"

namespace mmrtm {

struct NoiseEstimate {
  double meanLuminance = 0;  // over all pixels
  // Root mean square over pixels of the standard error of the luminance
  // mean, from the difference of the two replicates' means (Film::Noise).
  double rmsStandardError = 0;
  double relative = 0;  // rmsStandardError / meanLuminance
};

class Film;

// What a denoised display is made from (Film::DenoiserImages): the film's
// two halves, its even and its odd samples (independent estimates of the
// image: two independently scrambled nets, or independent numbers), each
// with the guides of its own samples, and the guides of all samples.
struct FilmHalves {
  uint32_t samples[2] = {0, 0};  // of the film's first pixel
  RGBImage color[2], albedo[2], normal[2];
  RGBImage albedoWhole, normalWhole;
};

// Agreement of two renders of the same scene within their noise: the mean
// over pixels and channels of z^2 = (a - b)^2 / (var_a + var_b), skipping
// pixels without variance (e.g. the background). About 1 when the two
// estimate the same image, 0 for identical images, well above 1 when they differ.
double MeanSquaredZScore(const Film& a, const Film& b);

class Film {
 public:
  Film(int width, int height);

  FilmView View() {
    return FilmView{width_,
                    height_,
                    mean_.data(),
                    m2_.data(),
                    work_.empty() ? nullptr : work_.data(),
                    evenLuminance_.data(),
                    denoiserInputs_.empty() ? nullptr : denoiserInputs_.data()};
  }
  void Reset();
  int Width() const { return width_; }
  int Height() const { return height_; }
  // Samples that every pixel has: all of them in a uniformly sampled film,
  // the fewest of any pixel after adaptive sampling (SetPixelSamples).
  uint32_t Samples() const { return samples_; }
  // Adds n samples to every pixel's count (a uniform pass).
  void AddSamples(uint32_t n);

  // Adaptive sampling: pixels with their own sample counts. A film is
  // uniform until SetPixelSamples; Reset makes it uniform again.
  bool Adaptive() const { return !pixelSamples_.empty(); }
  uint32_t PixelSamples(int x, int y) const { return Adaptive() ? pixelSamples_[(size_t)y * width_ + x] : samples_; }
  double MeanSamples() const;
  uint32_t MaxSamples() const;
  // Records the per-pixel counts after a pass that brought pixel i to
  // counts[i] samples (row-major, width x height values).
  void SetPixelSamples(std::vector<uint32_t> counts);

  // Per-pixel work (TraceCounters::Work of the pixel's samples), kept when
  // enabled: adaptive sampling weighs a pixel's noise by its cost.
  void TrackWork() { work_.assign((size_t)width_ * height_, 0.f); }
  bool TracksWork() const { return !work_.empty(); }
  float Work(int x, int y) const { return work_.empty() ? 0.f : work_[(size_t)y * width_ + x]; }

  // The denoised display's inputs (FilmView::denoiserInputs), kept when
  // enabled: the renderers then ask the integrator for its first-hit guides
  // (IntegratorSettings::firstHitGuides). The radiance's buffers are the
  // same to the bit either way.
  void TrackDenoiserInputs() { denoiserInputs_.assign((size_t)width_ * height_ * FilmView::kDenoiserInputFloats, 0.f); }
  bool TracksDenoiserInputs() const { return !denoiserInputs_.empty(); }
  // The halves and guides (std::logic_error without TrackDenoiserInputs or
  // with fewer than 2 samples in a pixel).
  FilmHalves DenoiserImages() const;

  RGB Mean(int x, int y) const;
  // The mean of the pixel's even samples (0, 2, 4 ...), kept with the
  // denoiser's inputs (black without them).
  RGB EvenMean(int x, int y) const;
  float Alpha(int x, int y) const { return mean_[4 * ((size_t)y * width_ + x) + 3]; }
  // Variance of the pixel's mean estimate, per channel, from the samples'
  // spread (0 before 2 samples): exact in expectation for independent
  // samples, above the error for stratified (Sobol') ones.
  RGB VarianceOfMean(int x, int y) const;
  // The image's relative noise, from the pixels' two replicates (even and
  // odd sample indices, independently scrambled): per pixel, the squared
  // difference of their mean luminances, scaled to the variance of the
  // whole mean, is an unbiased estimate of it with one degree of freedom,
  // for independent and stratified samples alike; summed over the pixels
  // it is a precise one. What noise targets stop on.
  NoiseEstimate Noise() const;

  RGBImage Linear() const;
  // VarianceOfMean of every pixel, laid out as Linear().
  RGBImage VarianceOfMeanImage() const;
  // 8-bit sRGB, row 0 at the top; 4 channels adds alpha (premultiplied colour).
  std::vector<uint8_t> ToneMapped(float exposure, ToneMapper op, int channels = 3) const;

  // Sample-parallel rendering: films of independent sample streams of one
  // image (other seeds, other processes) combine into one film as if all
  // their samples had been added to it, by summing their moments. Per
  // pixel, kMomentsPerPixel doubles: n mean (RGBA), M2 + n mean^2 (RGB),
  // and n0 and n0 times the even samples' mean luminance, with n the film's
  // samples and n0 its even ones. Sums in double: exact enough for the
  // variance of thousands of samples. Uniform films only: an adaptive
  // film's moments would need its counts (std::logic_error).
  static constexpr int kMomentsPerPixel = 9;
  std::vector<double> Moments() const;
  // The film whose samples are `samples` in all, from the element-wise sum
  // of the Moments() of films of this size (samples = the sum of theirs).
  // It is for reading: its replicates are the parts' (Noise), and samples
  // rendered into it would not continue them (Reset it first).
  static Film FromMoments(int width, int height, uint32_t samples, const std::vector<double>& moments);

 private:
  int width_, height_;
  uint32_t samples_ = 0;
  std::vector<uint32_t> pixelSamples_;  // empty: every pixel has samples_
  std::vector<float> mean_, m2_, work_, evenLuminance_, denoiserInputs_;
  // A film combined by FromMoments: the even samples of every pixel (the
  // parts' (n + 1) / 2 summed, more than half of the whole where parts had
  // odd counts); 0 for a rendered film, whose n samples hold (n + 1) / 2.
  uint32_t combinedEvenSamples_ = 0;
  uint32_t EvenSamples(uint32_t n) const { return combinedEvenSamples_ ? combinedEvenSamples_ : (n + 1) / 2; }
};

}  // namespace mmrtm
