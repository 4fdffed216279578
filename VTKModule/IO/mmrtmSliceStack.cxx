// A volume gathered slice by slice in the smallest exact voxel type
// (SliceStack, declared in mmrtmVolumeLoaderInternal.h).
#include "mmrtmVolumeLoaderInternal.h"

#include <type_traits>
#include <utility>

namespace mmrtm
{

namespace
{

// Calls f with a typed pointer to the voxels of type `type` at `bytes`.
template <typename F>
void WithVoxels(VoxelType type, uint8_t* bytes, F f)
{
  switch (type)
  {
    case VoxelType::UInt8:
      f(bytes);
      break;
    case VoxelType::Int16:
      f(reinterpret_cast<int16_t*>(bytes));
      break;
    case VoxelType::UInt16:
      f(reinterpret_cast<uint16_t*>(bytes));
      break;
    case VoxelType::Float32:
      f(reinterpret_cast<float*>(bytes));
      break;
  }
}

} // namespace

SliceStack::SliceStack(int64_t sliceVoxels, int slices)
  : sliceVoxels_(sliceVoxels)
  , slices_(slices)
{
}

void SliceStack::Put(int index, const float* values, const ValueStats& stats)
{
  const bool first = voxels_.empty();
  stats_.Add(stats);
  const VoxelType type = SmallestExactType(stats_);
  if (first)
  {
    type_ = type;
    voxels_.resize((size_t)(sliceVoxels_ * slices_ * VoxelTypeSize(type_)));
  }
  else if (type != type_)
  {
    Widen(type);
  }
  // Exact: the type holds every value put so far.
  WithVoxels(type_, voxels_.data(),
    [&](auto* voxels)
    {
      using T = std::remove_pointer_t<decltype(voxels)>;
      T* slice = voxels + (int64_t)index * sliceVoxels_;
      for (int64_t i = 0; i < sliceVoxels_; ++i)
        slice[i] = static_cast<T>(values[i]);
    });
}

void SliceStack::Widen(VoxelType type)
{
  std::vector<uint8_t> wider((size_t)(sliceVoxels_ * slices_ * VoxelTypeSize(type)));
  const int64_t count = sliceVoxels_ * slices_;
  WithVoxels(type_, voxels_.data(),
    [&](auto* from)
    {
      WithVoxels(type, wider.data(),
        [&](auto* to)
        {
          using T = std::remove_pointer_t<decltype(to)>;
          for (int64_t i = 0; i < count; ++i)
            to[i] = static_cast<T>(from[i]);
        });
    });
  voxels_ = std::move(wider);
  type_ = type;
}

void SliceStack::MoveInto(HostVolume& out)
{
  if (voxels_.empty())
    voxels_.resize((size_t)(sliceVoxels_ * slices_));
  out.type = type_;
  out.voxels = VoxelBuffer(std::move(voxels_));
}

} // namespace mmrtm
