// libFuzzer target: the images the project reads. Built once per format,
// MMRTM_FUZZ_FORMAT naming it: "png" (ReadPNG: baselines and masks) and
// "environment-map" (EnvironmentMap::Load: a Radiance .hdr, or a .pfm when
// the input starts with "PF"/"Pf", and the sampling tables built from it).
//
// Findings: anything but an image or an InputError; an image whose size
// does not match its pixels; an environment map with a texel or a sampling
// weight that is negative or not finite (it would put NaN into renders).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "FuzzScratch.h"
#include "environment_map.h"
#include "host_volume.h"  // InputError
#include "image_io.h"

#ifndef MMRTM_FUZZ_FORMAT
#error "MMRTM_FUZZ_FORMAT names the format this target fuzzes"
#endif

namespace {

void Require(bool condition) {
  if (!condition) std::abort();
}

void ReadPng(const uint8_t* data, size_t size) {
  const std::string path = mmrtm::fuzz::WriteScratchFile("input.png", data, size);
  int width = 0, height = 0, channels = 0;
  const std::vector<uint8_t> pixels = mmrtm::ReadPNG(path, &width, &height, &channels);
  Require(width > 0 && height > 0 && channels >= 1 && channels <= 4);
  Require(pixels.size() == (size_t)width * height * channels);
  mmrtm::fuzz::Outcome("an image of " + std::to_string(width) + " x " + std::to_string(height) + " pixels");
}

void LoadEnvironmentMap(const uint8_t* data, size_t size) {
  const bool pfm = size >= 2 && data[0] == 'P' && (data[1] == 'F' || data[1] == 'f');
  const std::string path = mmrtm::fuzz::WriteScratchFile(pfm ? "sky.pfm" : "sky.hdr", data, size);
  const auto map = mmrtm::EnvironmentMap::Load(path);
  Require(map->Width() > 0 && map->Height() > 0);
  Require(map->Texels().size() == (size_t)map->Width() * map->Height());
  for (const mmrtm::RGB& t : map->Texels())
    for (int c = 0; c < 3; ++c) Require(std::isfinite(t[c]) && t[c] >= 0);
  const mmrtm::EnvironmentView view = map->View();
  Require(std::isfinite(view.distribution.marginal.funcIntegral) && view.distribution.marginal.funcIntegral >= 0);
  mmrtm::fuzz::Outcome("a map of " + std::to_string(map->Width()) + " x " + std::to_string(map->Height()) + " texels");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string format = MMRTM_FUZZ_FORMAT;
  try {
    if (format == "png")
      ReadPng(data, size);
    else if (format == "environment-map")
      LoadEnvironmentMap(data, size);
    else
      std::abort();  // a target built with an unknown format
  } catch (const mmrtm::InputError& e) {
    mmrtm::fuzz::Outcome(e.what());
  }
  return 0;
}
