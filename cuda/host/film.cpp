#include "film.h"

#include "mmrtm/planted_defect.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mmrtm {

Film::Film(int width, int height) : width_(width), height_(height) { Reset(); }

void Film::Reset() {
  samples_ = 0;
  combinedEvenSamples_ = 0;
  pixelSamples_.clear();
  mean_.assign((size_t)width_ * height_ * 4, 0.f);
  m2_.assign((size_t)width_ * height_ * 3, 0.f);
  evenLuminance_.assign((size_t)width_ * height_, 0.f);
  if (!work_.empty()) TrackWork();
  if (!denoiserInputs_.empty()) TrackDenoiserInputs();
}

void Film::AddSamples(uint32_t n) {
  samples_ += n;
  for (uint32_t& c : pixelSamples_) c += n;
}

void Film::SetPixelSamples(std::vector<uint32_t> counts) {
  if (counts.size() != (size_t)width_ * height_)
    throw std::invalid_argument("Film::SetPixelSamples: " + std::to_string(counts.size()) + " counts for " +
                                std::to_string(width_) + " x " + std::to_string(height_) + " pixels");
  samples_ = counts.empty() ? 0 : *std::min_element(counts.begin(), counts.end());
  pixelSamples_ = std::move(counts);
}

double Film::MeanSamples() const {
  if (!Adaptive()) return samples_;
  double sum = 0;
  for (uint32_t c : pixelSamples_) sum += c;
  return sum / (double)pixelSamples_.size();
}

uint32_t Film::MaxSamples() const {
  return Adaptive() ? *std::max_element(pixelSamples_.begin(), pixelSamples_.end()) : samples_;
}

RGB Film::Mean(int x, int y) const {
  const float* m = &mean_[4 * ((size_t)y * width_ + x)];
  return RGB(m[0], m[1], m[2]);
}

RGB Film::EvenMean(int x, int y) const {
  if (denoiserInputs_.empty()) return RGB(0.f);
  const float* d = &denoiserInputs_[FilmView::kDenoiserInputFloats * ((size_t)y * width_ + x) + FilmView::kEvenRGB];
  return RGB(d[0], d[1], d[2]);
}

RGB Film::VarianceOfMean(int x, int y) const {
  const uint32_t n = PixelSamples(x, y);
  if (n < 2) return RGB(0.f);
  const float* s = &m2_[3 * ((size_t)y * width_ + x)];
  const float norm = 1.f / ((float)n * (float)(n - 1)) * (Planted(Defect::FilmVariance) ? 0.5f : 1.f);
  return RGB(s[0] * norm, s[1] * norm, s[2] * norm);
}

NoiseEstimate Film::Noise() const {
  NoiseEstimate e;
  double sumL = 0, sumVar = 0;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const double L = Luminance(Mean(x, y));
      sumL += L;
      // The even samples' mean m0 (n0 of them) and the odd ones' m1 (n1)
      // are independent estimates of the pixel (two independently
      // scrambled nets, or independent numbers), so E[(m0 - m1)^2] =
      // Var m0 + Var m1, and (m0 - m1)^2 n0 n1 / n^2 estimates the variance
      // of the whole mean without bias (exactly for n0 = n1; for odd n where
      // each replicate's variance goes as 1 / its samples). Luminance
      // directly: no bound on the channels' covariance is needed. The
      // samples' own spread (VarianceOfMean) would overstate a stratified
      // mean's error by 13-20 % (noise_target_check.py), so a target would
      // stop later than it needs to.
      const uint32_t n = PixelSamples(x, y), n0 = EvenSamples(n), n1 = n - n0;
      if (n0 == 0 || n1 == 0) continue;
      const double m0 = evenLuminance_[(size_t)y * width_ + x], m1 = ((double)n * L - (double)n0 * m0) / n1;
      sumVar += (m0 - m1) * (m0 - m1) * ((double)n0 * n1) / ((double)n * n);
    }
  const double n = (double)width_ * height_;
  e.meanLuminance = sumL / n;
  e.rmsStandardError = std::sqrt(sumVar / n);
  e.relative = e.meanLuminance > 0 ? e.rmsStandardError / e.meanLuminance : 0;
  return e;
}

std::vector<double> Film::Moments() const {
  if (Adaptive()) throw std::logic_error("Film::Moments: an adaptively sampled film has per-pixel counts");
  const size_t pixels = (size_t)width_ * height_;
  std::vector<double> out(pixels * kMomentsPerPixel);
  const double n = samples_;
  for (size_t i = 0; i < pixels; ++i) {
    double* o = &out[i * kMomentsPerPixel];
    for (int c = 0; c < 4; ++c) o[c] = n * mean_[4 * i + c];
    for (int c = 0; c < 3; ++c) o[4 + c] = m2_[3 * i + c] + n * (double)mean_[4 * i + c] * mean_[4 * i + c];
    const double n0 = EvenSamples(samples_);
    o[7] = n0;
    o[8] = n0 * evenLuminance_[i];
  }
  return out;
}

Film Film::FromMoments(int width, int height, uint32_t samples, const std::vector<double>& moments) {
  Film film(width, height);
  const size_t pixels = (size_t)width * height;
  if (moments.size() != pixels * kMomentsPerPixel)
    throw std::invalid_argument("Film::FromMoments: " + std::to_string(moments.size()) + " moments for " +
                                std::to_string(width) + " x " + std::to_string(height) + " pixels");
  film.samples_ = samples;
  if (samples == 0) return film;
  film.combinedEvenSamples_ = (uint32_t)std::llround(moments[7]);  // the same in every pixel of uniform films
  const double n = samples;
  for (size_t i = 0; i < pixels; ++i) {
    const double* m = &moments[i * kMomentsPerPixel];
    for (int c = 0; c < 4; ++c) film.mean_[4 * i + c] = (float)(m[c] / n);
    // M2 = sum over films of (M2 + n mean^2) - n mean^2 of the whole; never
    // below 0 (rounding where all samples agree).
    for (int c = 0; c < 3; ++c) film.m2_[3 * i + c] = (float)std::max(0.0, m[4 + c] - m[c] * m[c] / n);
    film.evenLuminance_[i] = m[7] > 0 ? (float)(m[8] / m[7]) : 0.f;
  }
  return film;
}

FilmHalves Film::DenoiserImages() const {
  if (!TracksDenoiserInputs()) throw std::logic_error("Film::DenoiserImages: the film keeps no denoiser inputs");
  FilmHalves h;
  const size_t pixels = (size_t)width_ * height_;
  const RGBImage blank{width_, height_, std::vector<RGB>(pixels)};
  for (RGBImage* image : {&h.color[0], &h.color[1], &h.albedo[0], &h.albedo[1], &h.normal[0], &h.normal[1],
                          &h.albedoWhole, &h.normalWhole})
    *image = blank;
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t n = PixelSamples((int)(i % width_), (int)(i / width_)), n0 = EvenSamples(n), n1 = n - n0;
    if (n0 == 0 || n1 == 0)
      throw std::logic_error("Film::DenoiserImages: a pixel has " + std::to_string(n) + " sample(s); halves need 2");
    const float* d = &denoiserInputs_[i * FilmView::kDenoiserInputFloats];
    const float* whole = &mean_[4 * i];
    // The odd samples' mean, from the whole's and the even ones': (n m - n0 m0) / n1.
    const auto odd = [&](float all, float even) { return ((float)n * all - (float)n0 * even) / (float)n1; };
    for (int c = 0; c < 3; ++c) {
      h.color[0].pixels[i][c] = d[FilmView::kEvenRGB + c];
      h.color[1].pixels[i][c] = odd(whole[c], d[FilmView::kEvenRGB + c]);
      h.albedoWhole.pixels[i][c] = d[FilmView::kAlbedo + c];
      h.normalWhole.pixels[i][c] = d[FilmView::kNormal + c];
      h.albedo[0].pixels[i][c] = d[FilmView::kEvenAlbedo + c];
      h.normal[0].pixels[i][c] = d[FilmView::kEvenNormal + c];
      h.albedo[1].pixels[i][c] = odd(d[FilmView::kAlbedo + c], d[FilmView::kEvenAlbedo + c]);
      h.normal[1].pixels[i][c] = odd(d[FilmView::kNormal + c], d[FilmView::kEvenNormal + c]);
    }
    if (i == 0) {
      h.samples[0] = n0;
      h.samples[1] = n1;
    }
  }
  return h;
}

RGBImage Film::Linear() const {
  RGBImage image{width_, height_, std::vector<RGB>((size_t)width_ * height_)};
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) image.pixels[(size_t)y * width_ + x] = Mean(x, y);
  return image;
}

RGBImage Film::VarianceOfMeanImage() const {
  RGBImage image{width_, height_, std::vector<RGB>((size_t)width_ * height_)};
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) image.pixels[(size_t)y * width_ + x] = VarianceOfMean(x, y);
  return image;
}

std::vector<uint8_t> Film::ToneMapped(float exposure, ToneMapper op, int channels) const {
  std::vector<uint8_t> out((size_t)width_ * height_ * channels);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      uint8_t* p = &out[((size_t)y * width_ + x) * channels];
      ToneMapPixel(Mean(x, y), exposure, op, p);
      if (channels == 4) p[3] = (uint8_t)(Clamp(Alpha(x, y), 0.f, 1.f) * 255.f + 0.5f);
    }
  return out;
}

double MeanSquaredZScore(const Film& a, const Film& b) {
  double sum = 0;
  int64_t n = 0;
  for (int y = 0; y < a.Height(); ++y)
    for (int x = 0; x < a.Width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double v = a.VarianceOfMean(x, y)[c] + b.VarianceOfMean(x, y)[c];
        if (v < 1e-9) continue;
        const double d = a.Mean(x, y)[c] - b.Mean(x, y)[c];
        sum += d * d / v;
        ++n;
      }
  return n ? sum / n : 0.0;
}

}  // namespace mmrtm
