// The export macro VTK_SLICER_MULTIMATERIALVOLUMERENDERING_MODULE_MRMLDISPLAYABLEMANAGER_EXPORT,
// from the header that either build route generates with that name:
// vtk_module_add_module (the PyPI Slicer core route) or
// generate_export_header (a Slicer extension build).
#pragma once

#include "vtkSlicerMultiMaterialVolumeRenderingModuleMRMLDisplayableManagerModule.h"
