// Tests of ImageDataToHostVolume, the mapper's way to its input's voxels:
// single-component scalars of a type the tracer samples natively are read in
// place (the volume holds a reference to the array, and never writes it);
// other types and components of interleaved scalars are converted into a
// buffer of the volume's own (Documentation/vtk-mapper.md, "What the mapper
// holds").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkShortArray.h>
#include <vtkUnsignedCharArray.h>

#include "mmrtmImageDataConversion.h"

using namespace mmrtm;

namespace {

// A 4 x 3 x 2 image whose scalars are `a` (filled with i % 50 per
// component c: + 100 * c).
void Attach(vtkImageData* image, vtkDataArray* a, int components) {
  image->SetDimensions(4, 3, 2);
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(24);
  for (int i = 0; i < 24; ++i)
    for (int c = 0; c < components; ++c) a->SetComponent(i, c, i % 50 + 100 * c);
  image->GetPointData()->SetScalars(a);
}

}  // namespace

TEST(ImageDataConversion, NativeScalarsAreReadInPlaceAndReferenced) {
  vtkNew<vtkImageData> image;
  vtkNew<vtkShortArray> a;
  Attach(image, a, 1);
  const int references = a->GetReferenceCount();
  {
    const HostVolume v = ImageDataToHostVolume(image, nullptr, 0, "scalars", Interpolation::Trilinear);
    EXPECT_EQ(v.type, VoxelType::Int16);
    EXPECT_TRUE(v.voxels.IsBorrowed());
    EXPECT_EQ(static_cast<const void*>(v.voxels.data()), a->GetVoidPointer(0)) << "the caller's voxels were copied";
    EXPECT_EQ(a->GetReferenceCount(), references + 1) << "the volume holds no reference to the array";
    image->GetPointData()->SetScalars(nullptr);  // the caller lets go: the volume keeps the array
    EXPECT_EQ(v.Value(23), 23.f);
  }
  EXPECT_EQ(a->GetReferenceCount(), references - 1) << "the volume's reference outlived it";
}

TEST(ImageDataConversion, OtherTypesAndInterleavedComponentsAreConverted) {
  vtkNew<vtkImageData> image;
  vtkNew<vtkDoubleArray> doubles;
  Attach(image, doubles, 1);
  const HostVolume d = ImageDataToHostVolume(image, nullptr, 0, "scalars", Interpolation::Trilinear);
  EXPECT_FALSE(d.voxels.IsBorrowed());
  EXPECT_EQ(d.type, VoxelType::UInt8);  // integers in [0, 255]: the smallest exact type
  EXPECT_EQ(d.Value(7), 7.f);

  vtkNew<vtkUnsignedCharArray> rgba;
  Attach(image, rgba, 4);
  const HostVolume green = ImageDataToHostVolume(image, nullptr, 1, "green", Interpolation::Trilinear);
  EXPECT_FALSE(green.voxels.IsBorrowed());
  EXPECT_EQ(green.type, VoxelType::UInt8);
  EXPECT_EQ(green.voxels.size(), 24u);
  EXPECT_EQ(green.Value(5), 105.f);
}

TEST(ImageDataConversion, NanVoxelsAreReplacedInACopyNotInTheCallersArray) {
  vtkNew<vtkImageData> image;
  vtkNew<vtkFloatArray> a;
  Attach(image, a, 1);
  a->SetValue(5, std::numeric_limits<float>::quiet_NaN());
  const HostVolume v = ImageDataToHostVolume(image, nullptr, 0, "scalars", Interpolation::Trilinear);
  EXPECT_EQ(v.nanVoxelsReplaced, 1);
  EXPECT_FALSE(v.voxels.IsBorrowed());
  EXPECT_EQ(v.Value(5), 0.f);  // the least finite value
  EXPECT_TRUE(std::isnan(a->GetValue(5))) << "the caller's array was written";

  a->SetValue(5, 5.f);  // finite float scalars are read in place
  const HostVolume finite = ImageDataToHostVolume(image, nullptr, 0, "scalars", Interpolation::Trilinear);
  EXPECT_TRUE(finite.voxels.IsBorrowed());
}
