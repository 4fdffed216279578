// Whether a CUDA device can be used, asked once per process and cached: a
// machine without a driver or a GPU answers with an error from
// cudaGetDeviceCount, which is reported once and makes the auto backend use
// the CPU. Host-only interface (no CUDA types), so that applications can ask
// without CUDA headers.
#pragma once

#include <cstddef>
#include <string>

namespace mmrtm {

struct CudaDeviceStatus {
  bool available = false;
  std::string reason;  // why not, when not available ("no CUDA driver", ...)
  std::string name;    // the device's name, when available
  int computeMajor = 0, computeMinor = 0;
  size_t totalMemory = 0;
};

// Device 0's status; the first call queries the runtime, later calls return
// the cached answer. Never throws.
const CudaDeviceStatus& CudaDevice();

}  // namespace mmrtm
