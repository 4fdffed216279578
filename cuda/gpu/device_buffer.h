// Device memory owned by one object (cudaMalloc / cudaFree). The free memory
// is checked before each allocation, so that a scene too large for the GPU
// fails with the sizes in the message instead of an out-of-memory error
// somewhere later. CUDA-only code (cuda/gpu).
#pragma once

#include <cstddef>
#include <string>
#include <utility>

#include "cuda_check.h"

namespace mmrtm {

// Thrown when the device has too little free memory for an allocation.
class DeviceMemoryError : public CudaError {
 public:
  using CudaError::CudaError;
};

class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  // `what` names the contents for messages ("voxels of proxy 0").
  DeviceBuffer(size_t bytes, const std::string& what) { Allocate(bytes, what); }
  ~DeviceBuffer() { Free(); }
  DeviceBuffer(DeviceBuffer&& o) noexcept : ptr_(std::exchange(o.ptr_, nullptr)), bytes_(std::exchange(o.bytes_, 0)) {}
  DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
    if (this != &o) {
      Free();
      ptr_ = std::exchange(o.ptr_, nullptr);
      bytes_ = std::exchange(o.bytes_, 0);
    }
    return *this;
  }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;

  void Allocate(size_t bytes, const std::string& what) {
    Free();
    if (bytes == 0) return;
    size_t freeBytes = 0, totalBytes = 0;
    MMRTM_CUDA_CHECK(cudaMemGetInfo(&freeBytes, &totalBytes));
    if (bytes > freeBytes)
      throw DeviceMemoryError("not enough GPU memory for " + what + ": " + Megabytes(bytes) + " needed, " +
                              Megabytes(freeBytes) + " free of " + Megabytes(totalBytes));
    const cudaError_t status = cudaMalloc(&ptr_, bytes);
    if (status != cudaSuccess) {
      cudaGetLastError();
      ptr_ = nullptr;
      throw DeviceMemoryError("cudaMalloc of " + Megabytes(bytes) + " for " + what +
                              " failed: " + cudaGetErrorString(status));
    }
    bytes_ = bytes;
  }

  void Upload(const void* host, size_t bytes) {
    MMRTM_CUDA_CHECK(cudaMemcpy(ptr_, host, bytes, cudaMemcpyHostToDevice));
  }
  void Download(void* host, size_t bytes) const {
    MMRTM_CUDA_CHECK(cudaMemcpy(host, ptr_, bytes, cudaMemcpyDeviceToHost));
  }

  void* Get() const { return ptr_; }
  template <typename T>
  T* As() const {
    return static_cast<T*>(ptr_);
  }
  size_t Bytes() const { return bytes_; }

  static std::string Megabytes(size_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

 private:
  void Free() {
    if (ptr_) cudaFree(ptr_);  // a destructor must not throw; a failed free leaves nothing to do
    ptr_ = nullptr;
    bytes_ = 0;
  }
  void* ptr_ = nullptr;
  size_t bytes_ = 0;
};

}  // namespace mmrtm
