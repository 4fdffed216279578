/**
 * @class   vtkMultiMaterialVolumeReader
 * @brief   reads a volume file or a DICOM series with the project's loader
 *
 * The loader of every MM-RTM application (Documentation/clinical-input.md)
 * as a VTK reader: NRRD, NIfTI, MetaImage, VTK image data, InVesalius
 * projects, and DICOM folders through ITK/GDCM (any transfer syntax GDCM
 * decodes, the series chosen by UID or description, rescaled to Hounsfield
 * units, gantry tilt kept as a shear, uneven spacing resampled; builds
 * without ITK read uncompressed DICOM only, see CanReadCompressedDICOM). The output
 * vtkImageData carries the world geometry (LPS millimetres) as origin,
 * spacing and direction matrix, so vtkMultiMaterialVolumeMapper places it
 * as the file says. The output's scalars are the loaded voxels themselves
 * (held once: a later execution reads the file again). Errors (a missing
 * file, a damaged series) are reported with the file named, and the output
 * is then empty.
 */
#ifndef vtkMultiMaterialVolumeReader_h
#define vtkMultiMaterialVolumeReader_h

#include "mmrtmIOModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <string> // for std::string

class MMRTMIO_EXPORT vtkMultiMaterialVolumeReader : public vtkImageAlgorithm
{
public:
  static vtkMultiMaterialVolumeReader* New();
  vtkTypeMacro(vtkMultiMaterialVolumeReader, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * A volume file or a DICOM folder.
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /**
   * DICOM folders with several series: the SeriesInstanceUID or the
   * SeriesDescription of the one to read (empty: the largest).
   */
  vtkSetStringMacro(Series);
  vtkGetStringMacro(Series);
  ///@}

  /**
   * The warnings of the last read (several series, tilt, uneven spacing),
   * one per line; empty when there were none.
   */
  const char* GetWarnings() { return this->Warnings.c_str(); }

  /**
   * Whether this build reads compressed DICOM (JPEG 2000 and the other
   * syntaxes GDCM decodes, through ITK). Builds without ITK, such as the
   * Python wheel for the PyPI VTK, read uncompressed DICOM only, through
   * vtkDICOMImageReader, and name the transfer syntax when they cannot.
   */
  static bool CanReadCompressedDICOM();

protected:
  vtkMultiMaterialVolumeReader();
  ~vtkMultiMaterialVolumeReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* FileName = nullptr;
  char* Series = nullptr;
  std::string Warnings;

private:
  vtkMultiMaterialVolumeReader(const vtkMultiMaterialVolumeReader&) = delete;
  void operator=(const vtkMultiMaterialVolumeReader&) = delete;
  bool Load();

  struct Loaded;
  Loaded* Volume = nullptr;
};

#endif
