// VTK's own image formats: XML image data (.vti) and legacy structured
// points (.vtk).
#include "mmrtmVolumeLoaderInternal.h"

#include <cstring>
#include <string>

#include <vtkDataReader.h>
#include <vtkFieldData.h>
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

namespace {

// vtkStructuredPointsReader (VTK 9.1 to 9.6) dereferences the field data it
// failed to read: a FIELD section it cannot parse, or any keyword that only
// starts with "field", crashes it (a fuzz finding). Reads the dataset's
// keywords with the reader's own parser first, as ReadMeshSimple does, up
// to the point or cell data, and refuses such a file. Anything else wrong
// is left to the reader, which reports it.
void CheckDatasetFieldData(const std::string& path) {
  vtkNew<vtkDataReader> reader;
  ReaderErrors errors(reader);  // its messages are the real reader's to give
  if (!reader->OpenVTKFile(path.c_str()) || !reader->ReadHeader(path.c_str())) return;
  char word[256];
  if (!reader->ReadString(word) || std::strncmp(reader->LowerCase(word), "dataset", 7) != 0 ||
      !reader->ReadString(word)) {
    reader->CloseVTKFile();
    return;
  }
  int integers[6];
  double reals[3];
  while (reader->ReadString(word)) {
    reader->LowerCase(word);
    bool read = true;
    if (std::strncmp(word, "field", 5) == 0) {
      vtkFieldData* fields = reader->ReadFieldData();
      if (!fields) {
        reader->CloseVTKFile();
        throw InputError(path + ": a FIELD section VTK's legacy reader cannot read (keyword '" + word + "')");
      }
      fields->Delete();
    } else if (std::strncmp(word, "extent", 6) == 0) {
      for (int i = 0; i < 6 && read; ++i) read = reader->Read(integers + i) != 0;
    } else if (std::strncmp(word, "dimensions", 10) == 0) {
      for (int i = 0; i < 3 && read; ++i) read = reader->Read(integers + i) != 0;
    } else if (std::strncmp(word, "aspect_ratio", 12) == 0 || std::strncmp(word, "spacing", 7) == 0 ||
               std::strncmp(word, "origin", 6) == 0) {
      for (int i = 0; i < 3 && read; ++i) read = reader->Read(reals + i) != 0;
    } else {
      break;  // point or cell data (where the dataset's keywords end), or an error the reader reports
    }
    if (!read) break;
  }
  reader->CloseVTKFile();
}

}  // namespace

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
  CheckDatasetFieldData(path);
  vtkImageData* image = RunReader(reader, path);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

}  // namespace mmrtm
