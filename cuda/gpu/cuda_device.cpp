#include "cuda_device.h"

#include <mutex>

#include <cuda_runtime_api.h>

namespace mmrtm {
namespace {

CudaDeviceStatus Query() {
  CudaDeviceStatus s;
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    // cudaErrorNoDevice, cudaErrorInsufficientDriver, ...: the runtime's
    // own words say which.
    s.reason = std::string("no usable CUDA device (") + cudaGetErrorString(status) + ")";
    cudaGetLastError();  // clear the sticky error state
    return s;
  }
  if (count == 0) {
    s.reason = "no CUDA device";
    return s;
  }
  cudaDeviceProp prop{};
  if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) {
    s.reason = "cannot query CUDA device 0";
    cudaGetLastError();
    return s;
  }
  // The fat binary holds sm_75, sm_86, sm_89 and sm_90 (+PTX for later
  // devices); anything older cannot run it.
  if (prop.major < 7 || (prop.major == 7 && prop.minor < 5)) {
    s.reason = std::string("CUDA device ") + prop.name + " has compute capability " + std::to_string(prop.major) + "." +
               std::to_string(prop.minor) + "; 7.5 or later is needed";
    return s;
  }
  s.available = true;
  s.name = prop.name;
  s.computeMajor = prop.major;
  s.computeMinor = prop.minor;
  s.totalMemory = prop.totalGlobalMem;
  return s;
}

}  // namespace

const CudaDeviceStatus& CudaDevice() {
  static std::once_flag once;
  static CudaDeviceStatus status;
  std::call_once(once, [] { status = Query(); });
  return status;
}

}  // namespace mmrtm
