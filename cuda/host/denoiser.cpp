#include "denoiser.h"

#include <dlfcn.h>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <vector>

namespace mmrtm {

static_assert(sizeof(RGB) == 3 * sizeof(float), "RGBImage pixels are passed to OIDN as packed float3");

// The few functions of OIDN's C API used here (OpenImageDenoise/oidn.h;
// the same signatures in 1.4 and 2.x).
struct Denoiser::Api {
  void* library = nullptr;
  void* (*newDevice)(int type) = nullptr;
  void (*setDeviceInt)(void* device, const char* name, int value) = nullptr;
  int (*getDeviceInt)(void* device, const char* name) = nullptr;
  void (*commitDevice)(void* device) = nullptr;
  int (*getDeviceError)(void* device, const char** message) = nullptr;
  void (*releaseDevice)(void* device) = nullptr;
  void* (*newFilter)(void* device, const char* type) = nullptr;
  void (*setSharedFilterImage)(void* filter, const char* name, void* ptr, int format, size_t width, size_t height,
                               size_t byteOffset, size_t bytePixelStride, size_t byteRowStride) = nullptr;
  void (*setFilterBool)(void* filter, const char* name, bool value) = nullptr;
  void (*setFilterInt)(void* filter, const char* name, int value) = nullptr;
  void (*setFilterProgressMonitor)(void* filter, bool (*monitor)(void* user, double n), void* user) = nullptr;
  void (*commitFilter)(void* filter) = nullptr;
  void (*executeFilter)(void* filter) = nullptr;
  void (*releaseFilter)(void* filter) = nullptr;
};

namespace {

constexpr int kDeviceTypeCpu = 1;  // OIDN_DEVICE_TYPE_CPU
constexpr int kFormatFloat3 = 3;   // OIDN_FORMAT_FLOAT3
constexpr int kErrorCancelled = 5;  // OIDN_ERROR_CANCELLED
// OIDN_QUALITY_HIGH, _BALANCED, _FAST (2.x).
constexpr int kQuality[] = {6, 5, 4};

// A filter's inputs, as FilterKey's bits.
constexpr int kColor = 1, kAlbedo = 2, kNormal = 4, kCleanGuides = 8;

// The progress monitor's answer: go on while the flag is not set.
bool GoOn(void* cancel, double) { return !(cancel && static_cast<const std::atomic<bool>*>(cancel)->load()); }

// The places to look, in order (denoiser.h).
std::vector<std::string> CandidatePaths() {
  if (const char* env = std::getenv("MMRTM_OIDN_LIBRARY"); env && *env) return {env};
  std::vector<std::string> paths;
#ifdef MMRTM_OIDN_DEFAULT_LIBRARY
  paths.push_back(MMRTM_OIDN_DEFAULT_LIBRARY);
#endif
  paths.push_back("libOpenImageDenoise.so.2");
  paths.push_back("libOpenImageDenoise.so.1");
  return paths;
}

// dlopen, and once more after the TBB that a wheel ships beside the library
// where the system has none.
void* OpenLibrary(const std::string& path, std::string* error) {
  if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
  *error = dlerror();
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(path).parent_path();
  std::error_code ec;
  if (folder.empty() || !fs::is_directory(folder, ec)) return nullptr;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.path().filename().string().rfind("libtbb.so", 0) == 0 &&
        dlopen(entry.path().c_str(), RTLD_NOW | RTLD_GLOBAL))
      if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) return handle;
  return nullptr;
}

// `name`, or `older` (OIDN 2 renamed the typed setters and getters: the
// same signatures).
template <typename F>
void Bind(void* library, const char* name, F* fn, const std::string& path, const char* older = nullptr) {
  *fn = reinterpret_cast<F>(dlsym(library, name));
  if (!*fn && older) *fn = reinterpret_cast<F>(dlsym(library, older));
  if (!*fn) throw DenoiserError(path + ": not Open Image Denoise (no " + name + ")");
}

}  // namespace

std::unique_ptr<Denoiser> Denoiser::Load(int threads) {
  std::string tried;
  auto api = std::make_unique<Api>();
  std::string path;
  for (const std::string& candidate : CandidatePaths()) {
    std::string error;
    if ((api->library = OpenLibrary(candidate, &error))) {
      path = candidate;
      break;
    }
    tried += "\n  " + candidate + ": " + error;
  }
  if (!api->library)
    throw DenoiserError(
        "Intel Open Image Denoise not found (scripts/install-dependencies.sh installs the `pyoidn` "
        "wheel into .venv, pip install mmrtm[denoise] with the Python package; MMRTM_OIDN_LIBRARY names a "
        "library). Tried:" +
        tried);
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // Its TBB opens libtbbbind with RTLD_DEEPBIND when the device starts,
  // which the sanitizer runtimes refuse by ending the process.
  throw DenoiserError("Intel Open Image Denoise is not started in a build with sanitizers (" + path +
                      ": its TBB opens libraries with RTLD_DEEPBIND, which the sanitizer runtimes refuse)");
#endif
  Api& a = *api;
  Bind(a.library, "oidnNewDevice", &a.newDevice, path);
  Bind(a.library, "oidnSetDeviceInt", &a.setDeviceInt, path, "oidnSetDevice1i");
  Bind(a.library, "oidnGetDeviceInt", &a.getDeviceInt, path, "oidnGetDevice1i");
  Bind(a.library, "oidnCommitDevice", &a.commitDevice, path);
  Bind(a.library, "oidnGetDeviceError", &a.getDeviceError, path);
  Bind(a.library, "oidnReleaseDevice", &a.releaseDevice, path);
  Bind(a.library, "oidnNewFilter", &a.newFilter, path);
  Bind(a.library, "oidnSetSharedFilterImage", &a.setSharedFilterImage, path);
  Bind(a.library, "oidnSetFilterBool", &a.setFilterBool, path, "oidnSetFilter1b");
  Bind(a.library, "oidnSetFilterInt", &a.setFilterInt, path, "oidnSetFilter1i");
  Bind(a.library, "oidnSetFilterProgressMonitorFunction", &a.setFilterProgressMonitor, path);
  Bind(a.library, "oidnCommitFilter", &a.commitFilter, path);
  Bind(a.library, "oidnExecuteFilter", &a.executeFilter, path);
  Bind(a.library, "oidnReleaseFilter", &a.releaseFilter, path);

  std::unique_ptr<Denoiser> d(new Denoiser());
  d->api_ = std::move(api);
  d->path_ = path;
  d->device_ = a.newDevice(kDeviceTypeCpu);
  if (!d->device_) throw DenoiserError(path + ": no CPU device");
  if (threads > 0) a.setDeviceInt(d->device_, "numThreads", threads);
  a.commitDevice(d->device_);
  const char* message = nullptr;
  if (a.getDeviceError(d->device_, &message) != 0)
    throw DenoiserError(path + ": " + (message ? message : "the device failed"));
  d->version_ = a.getDeviceInt(d->device_, "version");
  return d;
}

Denoiser::~Denoiser() {
  if (api_) {
    for (const auto& [key, filter] : filters_) api_->releaseFilter(filter);
    if (device_) api_->releaseDevice(device_);
  }
  // The library stays loaded: OIDN's threads may outlive the device briefly.
}

std::string Denoiser::Description() const {
  return "Intel Open Image Denoise " + std::to_string(version_ / 10000) + "." + std::to_string(version_ / 100 % 100) +
         "." + std::to_string(version_ % 100) + " (" + path_ + ")";
}

void* Denoiser::Filter(const FilterKey& key) {
  if (void*& filter = filters_[key]) return filter;
  const Api& a = *api_;
  void* filter = a.newFilter(device_, "RT");
  const int inputs = std::get<0>(key);
  if (inputs & kColor) a.setFilterBool(filter, "hdr", true);
  if (inputs & kCleanGuides) a.setFilterBool(filter, "cleanAux", true);
  if (version_ >= 20000) a.setFilterInt(filter, "quality", std::get<3>(key));
  return filters_[key] = filter;
}

RGBImage Denoiser::Execute(void* filter, const std::map<const char*, const RGBImage*>& inputs, int width, int height,
                           const std::atomic<bool>* cancel) {
  const Api& a = *api_;
  RGBImage out{width, height, std::vector<RGB>((size_t)width * height)};
  const auto share = [&](const char* name, const RGBImage& image) {
    if (image.width != width || image.height != height)
      throw DenoiserError(std::string("the ") + name + " image is not the colour's size");
    a.setSharedFilterImage(filter, name, const_cast<RGB*>(image.pixels.data()), kFormatFloat3, (size_t)width,
                           (size_t)height, 0, 0, 0);
  };
  for (const auto& [name, image] : inputs) share(name, *image);
  share("output", out);
  a.setFilterProgressMonitor(filter, GoOn, const_cast<std::atomic<bool>*>(cancel));
  a.commitFilter(filter);
  a.executeFilter(filter);
  const char* message = nullptr;
  const int error = a.getDeviceError(device_, &message);
  if (error == kErrorCancelled || (cancel && cancel->load())) return RGBImage{};
  if (error != 0) throw DenoiserError(path_ + ": " + (message ? message : "the filter failed"));
  return out;
}

RGBImage Denoiser::Denoise(const RGBImage& color, const RGBImage* albedo, const RGBImage* normal, bool cleanGuides,
                           const std::atomic<bool>* cancel) {
  if (!albedo) normal = nullptr;  // OIDN takes a normal only with an albedo
  const int inputs =
      kColor | (albedo ? kAlbedo : 0) | (normal ? kNormal : 0) | (albedo && cleanGuides ? kCleanGuides : 0);
  std::map<const char*, const RGBImage*> images{{"color", &color}};
  if (albedo) images["albedo"] = albedo;
  if (normal) images["normal"] = normal;
  return Execute(Filter({inputs, color.width, color.height, kQuality[(int)quality_]}), images, color.width,
                 color.height, cancel);
}

RGBImage Denoiser::DenoiseGuide(const RGBImage& guide, Guide which, const std::atomic<bool>* cancel) {
  const bool isAlbedo = which == Guide::Albedo;
  return Execute(Filter({isAlbedo ? kAlbedo : kNormal, guide.width, guide.height, kQuality[(int)quality_]}),
                 {{isAlbedo ? "albedo" : "normal", &guide}}, guide.width, guide.height, cancel);
}

}  // namespace mmrtm
