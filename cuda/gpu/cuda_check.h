// Checks the status of every CUDA runtime call (host code). A failure throws
// CudaError with the call, the place and CUDA's own message; nothing is
// ignored. CUDA-only code (cuda/gpu).
#pragma once

#include <stdexcept>
#include <string>

#include <cuda_runtime_api.h>

namespace mmrtm {

class CudaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline void CheckCuda(cudaError_t status, const char* call, const char* file, int line) {
  if (status == cudaSuccess) return;
  throw CudaError(std::string("CUDA error ") + cudaGetErrorName(status) + " (" + cudaGetErrorString(status) + ") in " +
                  call + " at " + file + ":" + std::to_string(line));
}

}  // namespace mmrtm

#define MMRTM_CUDA_CHECK(call) ::mmrtm::CheckCuda((call), #call, __FILE__, __LINE__)
