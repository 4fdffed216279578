// VTK's own image formats: XML image data (.vti) and legacy structured
// points (.vtk).
#include "mmrtmVolumeLoaderInternal.h"

#include <string>

#include <vtkNew.h>
#include <vtkStructuredPointsReader.h>
#include <vtkXMLImageDataReader.h>

namespace mmrtm {

// Scientific data without anatomy: the coordinates are taken as LPS as they
// are. VTI files may carry a Direction matrix, which vtkImageData keeps.

void LoadVti(const std::string& path, HostVolume& out, const VolumeLoadOptions& /*options*/) {
  vtkNew<vtkXMLImageDataReader> reader;
  if (!reader->CanReadFile(path.c_str())) throw InputError(path + ": not a VTK XML ImageData file");
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

void LoadLegacyVtk(const std::string& path, HostVolume& out, const VolumeLoadOptions& /*options*/) {
  vtkNew<vtkStructuredPointsReader> reader;
  reader->SetFileName(path.c_str());
  {
    ReaderErrors errors(reader);
    if (!reader->IsFileStructuredPoints()) {
      errors.ThrowIfFailed(path);
      throw InputError(path + ": not a legacy VTK STRUCTURED_POINTS dataset");
    }
  }
  vtkImageData* image = RunReader(reader, path);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

}  // namespace mmrtm
