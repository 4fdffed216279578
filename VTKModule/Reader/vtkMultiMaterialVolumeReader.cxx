#include "vtkMultiMaterialVolumeReader.h"

#include <cmath>
#include <exception>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDataObject.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkMatrix3x3.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include "mmrtmVolumeLoader.h"

vtkStandardNewMacro(vtkMultiMaterialVolumeReader);

// The volume of the last load, and what it was loaded from.
struct vtkMultiMaterialVolumeReader::Loaded
{
  mmrtm::HostVolume Volume;
  std::string FileName, Series;
  vtkMTimeType Time = 0;
  bool Ok = false;
  bool VoxelsGiven = false; // to the last output's scalars: a later RequestData loads them again
  double Origin[3], Spacing[3], Direction[9];
};

namespace
{
int VtkType(mmrtm::VoxelType t)
{
  switch (t)
  {
    case mmrtm::VoxelType::UInt8:
      return VTK_UNSIGNED_CHAR;
    case mmrtm::VoxelType::Int16:
      return VTK_SHORT;
    case mmrtm::VoxelType::UInt16:
      return VTK_UNSIGNED_SHORT;
    default:
      return VTK_FLOAT;
  }
}
}

vtkMultiMaterialVolumeReader::vtkMultiMaterialVolumeReader()
  : Volume(new Loaded)
{
  this->SetNumberOfInputPorts(0);
}

vtkMultiMaterialVolumeReader::~vtkMultiMaterialVolumeReader()
{
  this->SetFileName(nullptr);
  this->SetSeries(nullptr);
  delete this->Volume;
}

bool vtkMultiMaterialVolumeReader::Load()
{
  Loaded& v = *this->Volume;
  const std::string file = this->FileName ? this->FileName : "";
  const std::string series = this->Series ? this->Series : "";
  if (v.Time == this->GetMTime() && v.FileName == file && v.Series == series)
    return v.Ok;
  v = Loaded();
  v.FileName = file;
  v.Series = series;
  v.Time = this->GetMTime();
  this->Warnings.clear();
  try
  {
    mmrtm::VolumeLoadOptions options;
    options.series = series;
    options.warn = [this](const std::string& w) { this->Warnings += w + "\n"; };
    v.Volume = mmrtm::LoadVolume(file, "scalars", options);
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro(<< e.what());
    return false;
  }
  if (!this->Warnings.empty())
    vtkWarningMacro(<< this->Warnings);
  // index -> world = origin + [spacing-scaled direction columns] * index.
  const mmrtm::Affine3& m = v.Volume.indexToWorld;
  for (int c = 0; c < 3; ++c)
  {
    double length = 0;
    for (int r = 0; r < 3; ++r)
      length += static_cast<double>(m.m[r][c]) * m.m[r][c];
    v.Spacing[c] = std::sqrt(length);
    for (int r = 0; r < 3; ++r)
      v.Direction[3 * r + c] = v.Spacing[c] > 0 ? m.m[r][c] / v.Spacing[c] : (r == c ? 1.0 : 0.0);
  }
  for (int r = 0; r < 3; ++r)
    v.Origin[r] = m.m[r][3];
  v.Ok = true;
  return true;
}

int vtkMultiMaterialVolumeReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  if (!this->Load())
    return 0;
  const Loaded& v = *this->Volume;
  vtkInformation* info = outputVector->GetInformationObject(0);
  const int extent[6] = { 0, v.Volume.dims[0] - 1, 0, v.Volume.dims[1] - 1, 0, v.Volume.dims[2] - 1 };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  info->Set(vtkDataObject::SPACING(), v.Spacing, 3);
  info->Set(vtkDataObject::ORIGIN(), v.Origin, 3);
  info->Set(vtkDataObject::DIRECTION(), v.Direction, 9);
  vtkDataObject::SetPointDataActiveScalarInfo(info, VtkType(v.Volume.type), 1);
  return 1;
}

int vtkMultiMaterialVolumeReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  Loaded& v = *this->Volume;
  if (v.VoxelsGiven)
    v.Time = 0; // loaded again below
  if (!this->Load())
    return 0;
  vtkImageData* output = vtkImageData::GetData(outputVector);
  output->SetDimensions(v.Volume.dims[0], v.Volume.dims[1], v.Volume.dims[2]);
  output->SetSpacing(v.Spacing);
  output->SetOrigin(v.Origin);
  output->SetDirectionMatrix(v.Direction);
  // The output's scalars are the loaded voxels themselves, not a copy: the
  // array reads them in place (VTK never frees them) and an observer it
  // owns frees them when the array goes.
  auto* voxels = new mmrtm::VoxelBuffer(std::move(v.Volume.voxels));
  v.Volume.voxels = mmrtm::VoxelBuffer();
  v.VoxelsGiven = true;
  vtkNew<vtkCallbackCommand> owner;
  owner->SetClientData(voxels);
  owner->SetClientDataDeleteCallback([](void* buffer) { delete static_cast<mmrtm::VoxelBuffer*>(buffer); });
  auto scalars = vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(VtkType(v.Volume.type)));
  scalars->AddObserver(vtkCommand::DeleteEvent, owner);
  scalars->SetNumberOfComponents(1);
  scalars->SetVoidArray(const_cast<uint8_t*>(voxels->data()),
    static_cast<vtkIdType>(voxels->size() / mmrtm::VoxelTypeSize(v.Volume.type)), /*save=*/1);
  scalars->SetName("scalars");
  output->GetPointData()->SetScalars(scalars);
  return 1;
}

bool vtkMultiMaterialVolumeReader::CanReadCompressedDICOM()
{
  return mmrtm::DicomDecodesCompressedSyntaxes();
}

void vtkMultiMaterialVolumeReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Series: " << (this->Series ? this->Series : "(largest)") << "\n";
}
