// Tests of VoxelBuffer: borrowed memory is read in place and kept alive by
// its keeper, a write never reaches memory the buffer may not write (it
// copies first, and the address changes), and an adopted buffer writes in
// place only while no copy of it shares the memory.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "host_volume.h"

using namespace mmrtm;

namespace {

// Memory held by a shared vector, with a flag that says when it is freed.
struct Holder {
  std::vector<uint8_t> bytes{1, 2, 3, 4};
  bool* freed;
  explicit Holder(bool* f) : freed(f) {}
  ~Holder() { *freed = true; }
};

}  // namespace

TEST(VoxelBuffer, BorrowedBytesAreReadInPlaceAndKeptAlive) {
  bool freed = false;
  auto holder = std::make_shared<Holder>(&freed);
  const uint8_t* memory = holder->bytes.data();
  VoxelBuffer b = VoxelBuffer::Borrow(memory, 4, holder);
  holder.reset();  // the buffer's keeper is the last reference
  EXPECT_FALSE(freed);
  EXPECT_TRUE(b.IsBorrowed());
  EXPECT_EQ(b.data(), memory);
  EXPECT_EQ(b.size(), 4u);
  EXPECT_EQ(b[2], 3);
  VoxelBuffer copy = b;  // shares the memory: no copy of the bytes
  EXPECT_EQ(copy.data(), memory);
  b = VoxelBuffer();
  EXPECT_FALSE(freed);
  copy = VoxelBuffer();
  EXPECT_TRUE(freed);
}

TEST(VoxelBuffer, AWriteToBorrowedBytesCopiesFirst) {
  bool freed = false;
  auto holder = std::make_shared<Holder>(&freed);
  VoxelBuffer b = VoxelBuffer::Borrow(holder->bytes.data(), 4, holder);
  uint8_t* w = b.MutableData();
  EXPECT_NE(w, holder->bytes.data()) << "a write would reach the lender's memory";
  w[0] = 9;
  EXPECT_EQ(holder->bytes[0], 1);
  EXPECT_EQ(b[0], 9);
  EXPECT_FALSE(b.IsBorrowed());
  EXPECT_EQ(holder.use_count(), 1) << "the copy still holds the lender's memory";
}

TEST(VoxelBuffer, AnAdoptedBufferWritesInPlaceUnlessShared) {
  bool freed = false;
  auto holder = std::make_shared<Holder>(&freed);
  uint8_t* memory = holder->bytes.data();
  VoxelBuffer b = VoxelBuffer::Adopt(memory, 4, holder);
  holder.reset();
  EXPECT_EQ(b.MutableData(), memory);
  {
    const VoxelBuffer copy = b;
    uint8_t* w = b.MutableData();  // the copy reads the memory: b copies
    EXPECT_NE(w, memory);
    w[1] = 7;
    EXPECT_EQ(copy[1], 2);
  }
  EXPECT_TRUE(freed);  // b let go of it when it copied; the copy held it last
}

TEST(VoxelBuffer, ResizeAndAssignOwnTheirBytes) {
  bool freed = false;
  auto holder = std::make_shared<Holder>(&freed);
  VoxelBuffer b = VoxelBuffer::Borrow(holder->bytes.data(), 4, holder);
  b.resize(6);
  EXPECT_FALSE(b.IsBorrowed());
  EXPECT_EQ(b, VoxelBuffer(std::vector<uint8_t>{1, 2, 3, 4, 0, 0}));
  VoxelBuffer c = VoxelBuffer::Borrow(holder->bytes.data(), 4, holder);
  c.assign(c.begin() + 1, c.end());  // a range inside the borrowed memory
  EXPECT_EQ(c, VoxelBuffer(std::vector<uint8_t>{2, 3, 4}));
  c.assign(2, 5);
  EXPECT_EQ(c, VoxelBuffer(std::vector<uint8_t>{5, 5}));
  EXPECT_EQ(holder.use_count(), 1);
}

TEST(VoxelBuffer, NanReplacementCopiesBorrowedVoxelsOnlyWhenItMustWrite) {
  auto values = std::make_shared<std::vector<float>>(std::vector<float>{1.f, 2.f, 3.f, 4.f});
  HostVolume v;
  v.type = VoxelType::Float32;
  v.dims = {4, 1, 1};
  v.voxels = VoxelBuffer::Borrow(values->data(), 4 * sizeof(float), values);
  v.ReplaceNanVoxels();
  EXPECT_EQ(v.voxels.data(), reinterpret_cast<const uint8_t*>(values->data())) << "finite voxels were copied";
  (*values)[2] = std::numeric_limits<float>::quiet_NaN();
  v.ReplaceNanVoxels();
  EXPECT_EQ(v.nanVoxelsReplaced, 1);
  EXPECT_TRUE(std::isnan((*values)[2])) << "the lender's array was written";
  EXPECT_EQ(v.Value(2), 1.f);
  EXPECT_FALSE(v.voxels.IsBorrowed());
}
