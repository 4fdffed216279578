#include "environment_map.h"

#include <cmath>
#include <stdexcept>

#include "host_volume.h"
#include "image_io.h"

namespace mmrtm {

namespace {

// Builds a piecewise-constant CDF over n values; returns the integral over [0,1).
float BuildCdf(const float* func, int n, float* cdf) {
  cdf[0] = 0.f;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    sum += func[i] / (double)n;
    cdf[i + 1] = (float)sum;
  }
  if (sum > 0.0) {
    for (int i = 1; i <= n; ++i) cdf[i] = (float)(cdf[i] / sum);
  } else {
    for (int i = 1; i <= n; ++i) cdf[i] = (float)i / n;
  }
  cdf[n] = 1.f;
  return (float)sum;
}

}  // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<RGB> texels)
    : width_(width), height_(height), texels_(std::move(texels)) {
  if (width_ <= 0 || height_ <= 0 || (int64_t)texels_.size() != (int64_t)width_ * height_)
    throw InputError("environment map: bad size");
  for (const RGB& t : texels_)
    if (!(std::isfinite(t.r) && std::isfinite(t.g) && std::isfinite(t.b)) || t.r < 0.f || t.g < 0.f || t.b < 0.f)
      throw InputError("environment map: negative or non-finite texel");
  rowFunc_.resize((size_t)width_ * height_);
  rowCdf_.resize((size_t)(width_ + 1) * height_);
  marginalFunc_.resize(height_);
  marginalCdf_.resize(height_ + 1);
  for (int y = 0; y < height_; ++y) {
    float sinTheta = std::sin(kPi * (y + 0.5f) / height_);
    float* f = &rowFunc_[(size_t)y * width_];
    for (int x = 0; x < width_; ++x) f[x] = texels_[(size_t)y * width_ + x].MaxComponent() * sinTheta;
    marginalFunc_[y] = BuildCdf(f, width_, &rowCdf_[(size_t)y * (width_ + 1)]);
  }
  marginalIntegral_ = BuildCdf(marginalFunc_.data(), height_, marginalCdf_.data());
  rows_.resize(height_);
  for (int y = 0; y < height_; ++y)
    rows_[y] =
        Distribution1DView{&rowFunc_[(size_t)y * width_], &rowCdf_[(size_t)y * (width_ + 1)], width_, marginalFunc_[y]};
}

EnvironmentView EnvironmentMap::View() const {
  EnvironmentView v;
  v.texels = texels_.data();
  v.width = width_;
  v.height = height_;
  v.distribution.conditional = rows_.data();
  v.distribution.marginal = Distribution1DView{marginalFunc_.data(), marginalCdf_.data(), height_, marginalIntegral_};
  v.distribution.nu = width_;
  v.distribution.nv = height_;
  return v;
}

std::shared_ptr<EnvironmentMap> EnvironmentMap::Load(const std::string& path, float scale) {
  RGBImage image = ReadImageHDR(path);
  for (RGB& p : image.pixels) p *= scale;
  return std::make_shared<EnvironmentMap>(image.width, image.height, std::move(image.pixels));
}

std::shared_ptr<EnvironmentMap> EnvironmentMap::Constant(RGB radiance) {
  // A few rows so that the sin(theta) weighting of the sampling is close to
  // uniform on the sphere.
  const int w = 8, h = 64;
  return std::make_shared<EnvironmentMap>(w, h, std::vector<RGB>((size_t)w * h, radiance));
}

std::shared_ptr<EnvironmentMap> EnvironmentMap::DefaultSky(float intensity) {
  const int w = 8, h = 256;  // constant along the azimuth; rows fine enough not to band
  const RGB zenith(0.50f, 0.66f, 1.00f), horizon(1.00f, 0.98f, 0.95f), ground(0.30f, 0.27f, 0.24f);
  std::vector<RGB> texels((size_t)w * h);
  for (int y = 0; y < h; ++y) {
    float cosTheta = std::cos(kPi * (y + 0.5f) / h);  // +1 at the zenith
    RGB c;
    if (cosTheta >= 0.f) {
      float t = std::sqrt(cosTheta);
      c = horizon * (1.f - t) + zenith * t;
    } else {
      float t = std::min(1.f, -cosTheta * 4.f);
      c = horizon * (1.f - t) * 0.6f + ground * t;
    }
    for (int x = 0; x < w; ++x) texels[(size_t)y * w + x] = c * intensity;
  }
  return std::make_shared<EnvironmentMap>(w, h, std::move(texels));
}

}  // namespace mmrtm
