#include "mmrtmImageDataConversion.h"

#include <vector>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkType.h>

#include "mmrtmVolumeLoaderInternal.h"

namespace mmrtm
{
namespace
{

// One component of an interleaved array, as a contiguous buffer of its own.
template <typename T>
std::vector<uint8_t> ExtractComponent(const T* data, int64_t tuples, int components, int component)
{
  std::vector<uint8_t> bytes((size_t)tuples * sizeof(T));
  T* out = reinterpret_cast<T*>(bytes.data());
  for (int64_t i = 0; i < tuples; ++i)
    out[i] = data[i * components + component];
  return bytes;
}

} // namespace

HostVolume ImageDataToHostVolume(
  vtkImageData* image, vtkDataArray* scalars, int component, const std::string& name, Interpolation interpolation)
{
  if (!image)
    throw InputError(name + ": no input image");
  vtkDataArray* a = scalars ? scalars : image->GetPointData()->GetScalars();
  if (!a)
    throw InputError(name + ": the input image has no point scalars");
  const int components = a->GetNumberOfComponents();
  if (component < 0 || component >= components)
    throw InputError(
      name + ": component " + std::to_string(component) + " requested, the scalars have " + std::to_string(components));
  HostVolume out;
  out.name = name;
  out.source = name;
  out.interpolation = interpolation;
  const int* d = image->GetDimensions();
  out.dims = { d[0], d[1], d[2] };
  if (a->GetNumberOfTuples() != out.VoxelCount())
    throw InputError(name + ": the scalars hold " + std::to_string(a->GetNumberOfTuples()) + " tuples for " +
      std::to_string(out.VoxelCount()) + " points");
  if (components == 1)
  {
    StoreArrayVoxels(a, out.VoxelCount(), Rescale{}, ArrayHolder::Caller, out, name);
  }
  else
  {
    // The tracer reads a proxy's voxels contiguously: a component of
    // interleaved scalars is gathered into a buffer of its own, once, in
    // its own type when the tracer samples that type natively.
    const SourceType type = SourceTypeOfVtk(a->GetDataType(), name);
    switch (a->GetDataType())
    {
      vtkTemplateMacro({
        std::vector<uint8_t> values =
          ExtractComponent(static_cast<const VTK_TT*>(a->GetVoidPointer(0)), out.VoxelCount(), components, component);
        if (const std::optional<VoxelType> native = NativeVoxelType(type))
        {
          out.type = *native;
          out.voxels = std::move(values);
        }
        else
        {
          StoreVoxels(values.data(), type, out.VoxelCount(), Rescale{}, out);
        }
      });
      default:
        throw InputError(name + ": unsupported scalar type");
    }
  }
  out.indexToWorld = VtkImageIndexToWorld(image);
  out.ReplaceNanVoxels(); // the caller warns (nanVoxelsReplaced)
  out.Validate();
  return out;
}

} // namespace mmrtm
