// A VTK array's voxels as a HostVolume's buffer, read in place where the
// tracer can sample them as they are: a volume is then held once, by whoever
// held it before (a Slicer or ParaView image, a file reader's output).
#include "mmrtmVolumeLoaderInternal.h"

#include <memory>

#include <vtkDataArray.h>

namespace mmrtm
{
namespace
{

// A reference to `a` that the voxel buffer shares: the array (and so its
// memory) lives while any buffer reads it. The type stays erased so that
// cuda/host knows nothing of VTK.
std::shared_ptr<const void> ArrayReference(vtkDataArray* a)
{
  a->Register(nullptr);
  return std::shared_ptr<const void>(a, [](vtkDataArray* array) { array->UnRegister(nullptr); });
}

} // namespace

void StoreArrayVoxels(
  vtkDataArray* a, int64_t count, Rescale rescale, ArrayHolder holder, HostVolume& out, const std::string& path)
{
  if ((int64_t)a->GetNumberOfValues() < count)
    throw InputError(path + ": holds " + std::to_string((long long)a->GetNumberOfValues()) + " values, expected " +
      std::to_string(count) + " (truncated or corrupt?)");
  const SourceType type = SourceTypeOfVtk(a->GetDataType(), path);
  const std::optional<VoxelType> native = NativeVoxelType(type);
  // An array of another layout (structure of arrays, an implicit array)
  // gives GetVoidPointer a copy of its own: converted below instead.
  if (!native || !rescale.IsIdentity() || !a->HasStandardMemoryLayout())
  {
    StoreVoxels(a->GetVoidPointer(0), type, count, rescale, out);
    return;
  }
  out.type = *native;
  void* data = a->GetVoidPointer(0);
  const size_t bytes = (size_t)count * VoxelTypeSize(*native);
  out.voxels = holder == ArrayHolder::Loader ? VoxelBuffer::Adopt(data, bytes, ArrayReference(a))
                                             : VoxelBuffer::Borrow(data, bytes, ArrayReference(a));
}

} // namespace mmrtm
