# The wheel flavour (MMRTM_VTK_WHEEL): finds the VTK 9.6 SDK that builds
# against the PyPI vtk==9.6.0 wheel, making it with scripts/make-vtk-sdk.sh
# when none is there, and sets the wheel's install layout
# (Documentation/vtk-flavours.md).
#
# Where the SDK comes from, first found first:
# 1. VTK_DIR, when set (to any VTK 9.6 SDK, such as an unpacked vtk-sdk);
# 2. the `vtk-sdk==9.6.0` wheel in the build environment: scikit-build-core
#    puts its CMake package on the prefix path;
# 3. scripts/make-vtk-sdk.sh, from ../shared/vtk/vtk-9.6.0-source.tar.xz
#    (MMRTM_VTK_SOURCE), into ~/.cache/mmrtm (MMRTM_VTK_SDK_DIR).
set(MMRTM_VTK_WHEEL_VERSION 9.6.0)

find_package(Python3 REQUIRED COMPONENTS Interpreter Development.Module)
find_package(VTK ${MMRTM_VTK_WHEEL_VERSION} EXACT CONFIG QUIET COMPONENTS ${MMRTM_VTK_COMPONENTS})
if(NOT VTK_FOUND)
  if(VTK_DIR AND NOT VTK_DIR MATCHES "-NOTFOUND$")
    message(FATAL_ERROR "VTK_DIR=${VTK_DIR} is not a VTK ${MMRTM_VTK_WHEEL_VERSION} SDK with the components "
      "${MMRTM_VTK_COMPONENTS}: unset it to have scripts/make-vtk-sdk.sh make one")
  endif()
  unset(VTK_DIR CACHE)
  set(_mmrtm_sdk_args --python "${Python3_EXECUTABLE}" --cmake "${CMAKE_COMMAND}")
  if(CMAKE_MAKE_PROGRAM MATCHES "ninja")
    list(APPEND _mmrtm_sdk_args --ninja "${CMAKE_MAKE_PROGRAM}")
  endif()
  message(STATUS "Making the VTK ${MMRTM_VTK_WHEEL_VERSION} SDK (scripts/make-vtk-sdk.sh; about a minute, once)")
  execute_process(
    COMMAND bash "${CMAKE_CURRENT_SOURCE_DIR}/scripts/make-vtk-sdk.sh" ${_mmrtm_sdk_args}
    OUTPUT_VARIABLE _mmrtm_sdk_dir
    RESULT_VARIABLE _mmrtm_sdk_result
    OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(_mmrtm_sdk_result)
    message(FATAL_ERROR "scripts/make-vtk-sdk.sh could not make the VTK SDK (its messages are above)")
  endif()
  set(VTK_DIR "${_mmrtm_sdk_dir}" CACHE PATH "The VTK ${MMRTM_VTK_WHEEL_VERSION} SDK" FORCE)
  find_package(VTK ${MMRTM_VTK_WHEEL_VERSION} EXACT CONFIG REQUIRED COMPONENTS ${MMRTM_VTK_COMPONENTS})
endif()
message(STATUS "VTK ${VTK_VERSION} SDK: ${VTK_DIR}; libraries: ${VTK_WHEEL_LIBRARY_DIR}")

# The 3D Slicer classes (Slicer/, the PyPI Slicer core route) are built when
# the building Python has slicer-core-sdk and slicer-layer-dm-sdk (then
# scikit-build-core puts their CMake packages on the prefix path).
execute_process(
  COMMAND "${Python3_EXECUTABLE}" -c
    "import importlib.util as u, sys; sys.exit(0 if u.find_spec('slicer_core_sdk') and u.find_spec('slicer_layer_dm_sdk') else 1)"
  RESULT_VARIABLE _mmrtm_no_slicer_sdk)
set(_mmrtm_slicer_default ON)
if(_mmrtm_no_slicer_sdk)
  set(_mmrtm_slicer_default OFF)
endif()
option(MMRTM_ENABLE_SLICER "Build the 3D Slicer classes against slicer-core-sdk and slicer-layer-dm-sdk" ${_mmrtm_slicer_default})
message(STATUS "3D Slicer classes (MMRTM_ENABLE_SLICER): ${MMRTM_ENABLE_SLICER}")

# Layout inside site-packages: the package `mmrtm` holds its Python modules
# and its libraries; they find each other through $ORIGIN and VTK's libraries
# in the `vtkmodules` folder beside the package.
set(MMRTM_WHEEL_PACKAGE_DIR mmrtm)
set(CMAKE_INSTALL_RPATH "$ORIGIN;$ORIGIN/../vtkmodules")
set(CMAKE_BUILD_WITH_INSTALL_RPATH OFF)
