// Intel Open Image Denoise (OIDN), the denoiser of the denoised display
// (Documentation/denoising.md). The library is loaded at run time
// (dlopen), so the project builds and renders without it: from
// $MMRTM_OIDN_LIBRARY, else the path CMake found at configure time (the
// wheel that scripts/install-dependencies.sh puts in .venv), else the
// loader's search for libOpenImageDenoise.so.2 and .so.1. Its C API is the
// same in 1.4 and 2.x for what is used here (a CPU device, the "RT" filter,
// float3 images, a progress monitor); 2.x adds quality modes. Host-only.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <tuple>

#include "image_io.h"

namespace mmrtm {

// No library found, or the library failed: the message names what was tried.
class DenoiserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Denoiser {
 public:
  // OIDN 2's filter quality (1.4 has one, about Balanced's): Balanced, the
  // default; Fast, faster and a little farther from the truth; High, a
  // little closer and much slower with clean guides (the figures:
  // Documentation/denoising.md).
  enum class Quality { High, Balanced, Fast };

  // Loads the library and makes a device with `threads` threads (0: OIDN's
  // default, all). Throws DenoiserError.
  static std::unique_ptr<Denoiser> Load(int threads = 0);
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  // "Intel Open Image Denoise 2.5.1 (/path/libOpenImageDenoise.so.2.5.1)".
  std::string Description() const;
  int Version() const { return version_; }  // 20501 for 2.5.1
  void SetQuality(Quality quality) { quality_ = quality; }

  // The "RT" filter on linear HDR colour, guided by albedo and normal
  // images of the same size (either may be null; a normal only with an
  // albedo). `cleanGuides`: the guides are noise-free, as DenoiseGuide
  // makes them (OIDN's cleanAux). Returns an empty image when `cancel`
  // became true while it ran. Throws DenoiserError. Filters are kept per
  // image size and inputs, so a second call of a size costs no set-up: not
  // thread-safe (one caller at a time).
  RGBImage Denoise(const RGBImage& color, const RGBImage* albedo, const RGBImage* normal, bool cleanGuides = false,
                   const std::atomic<bool>* cancel = nullptr);

  // A noisy guide denoised (OIDN's prefiltering of auxiliary images), for
  // Denoise's cleanGuides. Empty when cancelled.
  enum class Guide { Albedo, Normal };
  RGBImage DenoiseGuide(const RGBImage& guide, Guide which, const std::atomic<bool>* cancel = nullptr);

 private:
  struct Api;
  // A committed filter: its inputs' kind and size.
  using FilterKey = std::tuple<int, int, int, int>;  // inputs (bits), width, height, quality
  Denoiser() = default;
  void* Filter(const FilterKey& key);
  RGBImage Execute(void* filter, const std::map<const char*, const RGBImage*>& inputs, int width, int height,
                   const std::atomic<bool>* cancel);
  std::unique_ptr<Api> api_;
  void* device_ = nullptr;
  std::string path_;
  int version_ = 0;
  Quality quality_ = Quality::Balanced;
  std::map<FilterKey, void*> filters_;
};

}  // namespace mmrtm
