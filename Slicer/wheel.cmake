# The PyPI Slicer core route: the extension's MRML, Logic and MRMLDM classes
# as VTK modules of the MM-RTM wheel (MMRTM_VTK_WHEEL), built against
# slicer-core-sdk and slicer-layer-dm-sdk (found in the building Python) and
# the VTK 9.6 SDK, wrapped as the Python package `mmrtm_slicer`, which
# registers itself in the `slicer` meta-package (`from slicer import ...`).
set(MMRTM_SLICER_CORE_WHEEL ON)
# Shared: the three libraries and their Python modules share one copy of
# each class (the pipeline factory is a singleton).
set(BUILD_SHARED_LIBS ON)

# ITK's package inside slicer-core-sdk asks for VTK through a path that no
# longer exists, and would find Debian's VTK 9.1: point it at the 9.6 SDK.
set(ENV{VTK_DIR} "${VTK_DIR}")
# No COMPONENTS: the packages' component check looks for targets that are
# not there (Slicer::VTK::...).
find_package(Slicer CONFIG REQUIRED)
find_package(SlicerLayerDM CONFIG REQUIRED)

# Beside the VTK wheel's libraries, those of the Slicer core, LayerDM and
# mmrtm; --as-needed keeps the ~100 ITK libraries Slicer's targets name out
# of what loads.
set(CMAKE_INSTALL_RPATH "$ORIGIN;$ORIGIN/../vtkmodules;$ORIGIN/../slicer_core;$ORIGIN/../slicer_core/third_party.libs;$ORIGIN/../slicer_layer_dm;$ORIGIN/../mmrtm")
add_link_options(LINKER:--as-needed)

set(module_dir ${CMAKE_CURRENT_SOURCE_DIR}/MultiMaterialVolumeRendering)
vtk_module_scan(
  MODULE_FILES     ${module_dir}/MRML/vtk.module ${module_dir}/Logic/vtk.module ${module_dir}/MRMLDM/vtk.module
  REQUEST_MODULES  MMRTM::SlicerMRML MMRTM::SlicerLogic MMRTM::SlicerMRMLDisplayableManager
  PROVIDES_MODULES mmrtm_slicer_modules)
vtk_module_build(
  MODULES             ${mmrtm_slicer_modules}
  PACKAGE             MMRTMSlicer
  LIBRARY_DESTINATION mmrtm_slicer
  INSTALL_HEADERS     OFF)
vtk_module_wrap_python(
  MODULES             ${mmrtm_slicer_modules}
  TARGET              MMRTM::SlicerPython
  PYTHON_PACKAGE      "mmrtm_slicer"
  MODULE_DESTINATION  "."
  LIBRARY_DESTINATION mmrtm_slicer
  SOABI               "${Python3_SOABI}"
  BUILD_STATIC        OFF
  INSTALL_HEADERS     OFF)

install(FILES ${module_dir}/Python/mmrtm_slicer/__init__.py DESTINATION mmrtm_slicer)
# `from slicer import vtkMRMLMultiMaterialVolumeRenderingDisplayNode`: the
# slicer meta-package imports every slicer/slicer_*.py beside it.
install(FILES ${module_dir}/Python/slicer/slicer_mmrtm.py DESTINATION slicer)
# The same layout in the build tree, for tests run from it.
file(COPY ${module_dir}/Python/mmrtm_slicer/__init__.py DESTINATION ${CMAKE_BINARY_DIR}/mmrtm_slicer)
