// Intel Open Image Denoise (OIDN) for the denoised preview
// (Documentation/denoising.md): a biased, clearly labelled extra image,
// never the unbiased one. The library is loaded at run time (dlopen), so
// the project builds and renders without it: from $MMRTM_OIDN_LIBRARY, else
// the path CMake found at configure time (the `oidn` wheel that
// scripts/install-dependencies.sh puts in .venv), else the loader's search
// for libOpenImageDenoise.so.2 and .so.1. Its C API is the same in 1.4 and
// 2.x for what is used here (a CPU device, the "RT" filter, float3 images).
// Host-only.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "image_io.h"

namespace mmrtm {

// No library found, or the library failed: the message names what was tried.
class DenoiserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Denoiser {
 public:
  // Loads the library and makes a device with `threads` threads (0: OIDN's
  // default, all). Throws DenoiserError.
  static std::unique_ptr<Denoiser> Load(int threads = 0);
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  // "Intel Open Image Denoise 1.4.3 (/path/libOpenImageDenoise.so.1.4.3)".
  std::string Description() const;

  // The "RT" filter on linear HDR colour, guided by first-hit albedo and
  // normal images of the same size (either may be null). Throws DenoiserError.
  RGBImage Denoise(const RGBImage& color, const RGBImage* albedo, const RGBImage* normal) const;

 private:
  struct Api;
  Denoiser() = default;
  std::unique_ptr<Api> api_;
  void* device_ = nullptr;
  std::string path_;
  int version_ = 0;
};

}  // namespace mmrtm
