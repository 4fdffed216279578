// An equirectangular environment (the environment light) with the tables of
// its importance-sampling distribution. Host-only set-up code.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mmrtm/lights.h"

namespace mmrtm {

class EnvironmentMap {
 public:
  // texels: width*height linear RGB, row 0 at the zenith (+z).
  EnvironmentMap(int width, int height, std::vector<RGB> texels);

  // An equirectangular Radiance .hdr (RGBE) or .pfm file, times `scale`.
  static std::shared_ptr<EnvironmentMap> Load(const std::string& path, float scale = 1.f);
  // The same radiance from every direction.
  static std::shared_ptr<EnvironmentMap> Constant(RGB radiance);
  // The default sky: a bright zenith fading to a white horizon over a dim
  // warm ground, so that a volume is lit from above and softly from below.
  static std::shared_ptr<EnvironmentMap> DefaultSky(float intensity = 1.f);

  EnvironmentView View() const;
  int Width() const { return width_; }
  int Height() const { return height_; }
  const std::vector<RGB>& Texels() const { return texels_; }

 private:
  int width_, height_;
  std::vector<RGB> texels_;
  // Sampling tables: per row a piecewise-constant distribution over u
  // (texel max-component times sin(theta)), and a marginal over rows.
  std::vector<float> rowFunc_, rowCdf_, marginalFunc_, marginalCdf_;
  std::vector<Distribution1DView> rows_;
  float marginalIntegral_ = 0.f;
};

}  // namespace mmrtm
