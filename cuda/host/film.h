// The host film: owns the accumulation buffers behind a FilmView, and turns
// them into images and noise figures. Host-only.
#pragma once

#include <cstdint>
#include <vector>

#include "image_io.h"
#include "mmrtm/film.h"
#include "mmrtm/tonemap.h"

namespace mmrtm {

struct NoiseEstimate {
  double meanLuminance = 0;     // over all pixels
  // Root mean square over pixels of the standard error of the luminance
  // mean, bounded from above by the channels' standard errors (Film::Noise).
  double rmsStandardError = 0;
  double relative = 0;          // rmsStandardError / meanLuminance
};

class Film;

// Agreement of two renders of the same scene within their noise: the mean
// over pixels and channels of z^2 = (a - b)^2 / (var_a + var_b), skipping
// pixels without variance (e.g. the background). About 1 when the two
// estimate the same image, 0 for identical images, well above 1 when they differ.
double MeanSquaredZScore(const Film& a, const Film& b);

class Film {
 public:
  Film(int width, int height);

  FilmView View() { return FilmView{width_, height_, mean_.data(), m2_.data()}; }
  void Reset();
  int Width() const { return width_; }
  int Height() const { return height_; }
  uint32_t Samples() const { return samples_; }
  void AddSamples(uint32_t n) { samples_ += n; }

  RGB Mean(int x, int y) const;
  float Alpha(int x, int y) const { return mean_[4 * ((size_t)y * width_ + x) + 3]; }
  // Variance of the pixel's mean estimate, per channel (0 before 2 samples).
  RGB VarianceOfMean(int x, int y) const;
  NoiseEstimate Noise() const;

  RGBImage Linear() const;
  // VarianceOfMean of every pixel, laid out as Linear().
  RGBImage VarianceOfMeanImage() const;
  // 8-bit sRGB, row 0 at the top; 4 channels adds alpha (premultiplied colour).
  std::vector<uint8_t> ToneMapped(float exposure, ToneMapper op, int channels = 3) const;

  // Sample-parallel rendering: films of independent sample streams of one
  // image (other seeds, other processes) combine into one film as if all
  // their samples had been added to it, by summing their moments. Per
  // pixel, kMomentsPerPixel doubles: n mean (RGBA) and M2 + n mean^2 (RGB),
  // with n the film's samples. Sums in double: exact enough for the
  // variance of thousands of samples.
  static constexpr int kMomentsPerPixel = 7;
  std::vector<double> Moments() const;
  // The film whose samples are `samples` in all, from the element-wise sum
  // of the Moments() of films of this size (samples = the sum of theirs).
  static Film FromMoments(int width, int height, uint32_t samples, const std::vector<double>& moments);

 private:
  int width_, height_;
  uint32_t samples_ = 0;
  std::vector<float> mean_, m2_;
};

}  // namespace mmrtm
