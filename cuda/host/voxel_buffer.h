// The voxel bytes of a HostVolume: owned, or borrowed from memory that
// another holder keeps alive (an array the caller of the VTK mapper holds, a
// file reader's array taken over whole). Reading is the same either way, so a
// volume is held once however it arrived. Host-only set-up code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace mmrtm {

class VoxelBuffer {
 public:
  using value_type = uint8_t;
  using const_iterator = const uint8_t*;

  VoxelBuffer() = default;
  VoxelBuffer(std::vector<uint8_t> bytes) : owned_(std::move(bytes)) {}  // NOLINT: a byte vector is a buffer

  // Reads `bytes` bytes at `data` in place. `keeper` keeps them alive while
  // any buffer shares it (its deleter releases what holds the memory, e.g. a
  // VTK array's reference). The memory is another's to write: a write
  // through MutableData first copies it.
  static VoxelBuffer Borrow(const void* data, size_t bytes, std::shared_ptr<const void> keeper);
  // As Borrow, for memory that nothing but this buffer reads or writes from
  // now on (a reader's array that outlives its reader here only): writes go
  // in place while no copy of this buffer shares it.
  static VoxelBuffer Adopt(void* data, size_t bytes, std::shared_ptr<const void> keeper);

  const uint8_t* data() const { return keeper_ ? borrowed_ : owned_.data(); }
  size_t size() const { return keeper_ ? borrowedBytes_ : owned_.size(); }
  bool empty() const { return size() == 0; }
  const uint8_t& operator[](size_t i) const { return data()[i]; }
  const uint8_t* begin() const { return data(); }
  const uint8_t* end() const { return data() + size(); }

  // Whether the bytes are another holder's memory, read in place.
  bool IsBorrowed() const { return keeper_ != nullptr; }

  // The bytes, for writing. Memory this buffer may not write (borrowed, or
  // adopted and shared with a copy of this buffer) is copied into a buffer
  // of its own first, so that a write never reaches a caller's array: the
  // address then changes, which is how a Scene and the GPU backend tell new
  // voxels from old.
  uint8_t* MutableData();

  // These leave the buffer owning its bytes (borrowed ones are let go).
  void resize(size_t bytes);  // keeps the first bytes; new ones are 0
  void assign(size_t bytes, uint8_t value);
  void assign(const uint8_t* first, const uint8_t* last);

  // Byte-wise equality (of the values, wherever they live).
  friend bool operator==(const VoxelBuffer& a, const VoxelBuffer& b);
  friend bool operator!=(const VoxelBuffer& a, const VoxelBuffer& b) { return !(a == b); }

 private:
  void Release();  // drops a borrowed buffer, keeping nothing

  std::vector<uint8_t> owned_;
  // Borrowed memory: when keeper_ is set, data() and size() are these.
  uint8_t* borrowed_ = nullptr;
  size_t borrowedBytes_ = 0;
  std::shared_ptr<const void> keeper_;
  bool writable_ = false;  // adopted: may be written while keeper_ is not shared
};

}  // namespace mmrtm
