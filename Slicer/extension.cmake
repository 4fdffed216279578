# The extension route: this folder as the top of a Slicer extension build,
# as Slicer's extension template (Utilities/Templates/Extensions). It cannot
# be built on these machines (no Slicer application or build tree; see
# README.md); the PyPI Slicer core route (wheel.cmake) builds and tests the
# same classes.

#-----------------------------------------------------------------------------
# Extension meta-information. The addresses are placeholders, as in Slicer's
# template: set them to the project's public repository before submitting
# the extension to the Slicer Extensions Index.
set(EXTENSION_HOMEPAGE "https://www.example.com/mmrtm/Documentation/slicer.md")
set(EXTENSION_CATEGORY "Rendering")
set(EXTENSION_CONTRIBUTORS "MM-RTM developers")
set(EXTENSION_DESCRIPTION "Physically based volume rendering (multi-material radiative transfer, Xu et al. 2025) as a rendering method of the Volume Rendering module: a path tracer that refines while the view is idle, with the Volume Rendering presets and a segmentation's segments as distinct materials.")
set(EXTENSION_ICONURL "https://www.example.com/mmrtm/Documentation/images/default-render.png")
set(EXTENSION_SCREENSHOTURLS "https://www.example.com/mmrtm/Documentation/images/slicer-head-ct-bone.png")
set(EXTENSION_DEPENDS "SlicerLayerDisplayableManager")

#-----------------------------------------------------------------------------
# Extension dependencies
find_package(Slicer REQUIRED)
include(${Slicer_USE_FILE})
find_package(SlicerLayerDisplayableManager REQUIRED)

#-----------------------------------------------------------------------------
# The tracer and the VTK mapper module, from this repository, compiled with
# Slicer's VTK (the same sources as every other flavour). Slicer reads DICOM
# itself, so the project's ITK reader is not built.
set(MMRTM_SOURCE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/..)
set(MMRTM_DATA_DIR ${MMRTM_SOURCE_DIR}/Data)
set(MMRTM_ENABLE_ITK OFF)
set(MMRTM_WRAP_PYTHON OFF)  # Slicer wraps the module libraries itself
set(MMRTM_VTK_WHEEL OFF)
include(CheckLanguage)
check_language(CUDA)
if(CMAKE_CUDA_COMPILER)
  set(MMRTM_ENABLE_CUDA ON)
  set(CMAKE_CUDA_ARCHITECTURES "75-real;86-real;89-real;90")
  set(CMAKE_CUDA_RUNTIME_LIBRARY Static)
  enable_language(CUDA)
endif()
add_subdirectory(${MMRTM_SOURCE_DIR}/cuda ${CMAKE_BINARY_DIR}/mmrtm-tracer)
add_subdirectory(${MMRTM_SOURCE_DIR}/Labels ${CMAKE_BINARY_DIR}/mmrtm-labels)
add_subdirectory(${MMRTM_SOURCE_DIR}/VTKModule ${CMAKE_BINARY_DIR}/mmrtm-vtk)

#-----------------------------------------------------------------------------
# Extension modules
add_subdirectory(MultiMaterialVolumeRendering)

#-----------------------------------------------------------------------------
include(${Slicer_EXTENSION_GENERATE_CONFIG})
include(${Slicer_EXTENSION_CPACK})
