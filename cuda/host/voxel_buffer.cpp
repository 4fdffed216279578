#include "voxel_buffer.h"

#include <algorithm>
#include <cstring>

namespace mmrtm {

VoxelBuffer VoxelBuffer::Borrow(const void* data, size_t bytes, std::shared_ptr<const void> keeper) {
  VoxelBuffer b = Adopt(const_cast<void*>(data), bytes, std::move(keeper));
  b.writable_ = false;
  return b;
}

VoxelBuffer VoxelBuffer::Adopt(void* data, size_t bytes, std::shared_ptr<const void> keeper) {
  VoxelBuffer b;
  if (!keeper) {  // nothing keeps the memory alive: hold a copy instead
    const auto* p = static_cast<const uint8_t*>(data);
    b.owned_.assign(p, p + bytes);
    return b;
  }
  b.borrowed_ = static_cast<uint8_t*>(data);
  b.borrowedBytes_ = bytes;
  b.keeper_ = std::move(keeper);
  b.writable_ = true;
  return b;
}

uint8_t* VoxelBuffer::MutableData() {
  if (!keeper_) return owned_.data();
  // use_count counts the buffers sharing the keeper: one means no copy of
  // this buffer reads the memory.
  if (writable_ && keeper_.use_count() == 1) return borrowed_;
  std::vector<uint8_t> copy(borrowed_, borrowed_ + borrowedBytes_);
  Release();
  owned_ = std::move(copy);
  return owned_.data();
}

void VoxelBuffer::Release() {
  borrowed_ = nullptr;
  borrowedBytes_ = 0;
  keeper_.reset();
  writable_ = false;
}

void VoxelBuffer::resize(size_t bytes) {
  if (keeper_) {
    std::vector<uint8_t> kept(borrowed_, borrowed_ + std::min(bytes, borrowedBytes_));
    Release();
    owned_ = std::move(kept);
  }
  owned_.resize(bytes);
}

void VoxelBuffer::assign(size_t bytes, uint8_t value) {
  Release();
  owned_.assign(bytes, value);
}

void VoxelBuffer::assign(const uint8_t* first, const uint8_t* last) {
  // The range may lie in the borrowed memory: copy before letting it go.
  std::vector<uint8_t> bytes(first, last);
  Release();
  owned_ = std::move(bytes);
}

bool operator==(const VoxelBuffer& a, const VoxelBuffer& b) {
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), a.size()) == 0);
}

}  // namespace mmrtm
