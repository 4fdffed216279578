# Part of the VTK 9.6 SDK that scripts/make-vtk-sdk.sh makes: included first
# by its vtk-config.cmake. The SDK carries no VTK library; its imported
# targets name ${VTK_WHEEL_LIBRARY_DIR}/libvtk*.so, the libraries of the PyPI
# `vtk` wheel installed in the Python that builds against it (the build
# environment of `pip install`, or a venv). Set VTK_WHEEL_LIBRARY_DIR to the
# wheel's `vtkmodules` folder to choose it yourself.
if(NOT VTK_WHEEL_LIBRARY_DIR)
  # VTK_VERSION is not set yet here: the SDK's version is its folder's name.
  get_filename_component(_vtk_sdk_data "${CMAKE_CURRENT_LIST_DIR}/../.." ABSOLUTE)
  get_filename_component(_vtk_sdk_data "${_vtk_sdk_data}" NAME)
  string(REGEX REPLACE "^vtk-(.*)\\.data$" "\\1" _vtk_sdk_version "${_vtk_sdk_data}")
  set(_vtk_wheel_python "${Python3_EXECUTABLE}")
  if(NOT _vtk_wheel_python)
    set(_vtk_wheel_python "${Python_EXECUTABLE}")
  endif()
  if(NOT _vtk_wheel_python)
    find_program(_vtk_wheel_python NAMES python3 python)
  endif()
  # find_spec locates the package without importing it (no VTK library loads).
  execute_process(
    COMMAND "${_vtk_wheel_python}" -c
      "import importlib.metadata as m, importlib.util as u; s = u.find_spec('vtkmodules'); print(m.version('vtk') + ';' + s.submodule_search_locations[0])"
    OUTPUT_VARIABLE _vtk_wheel_found
    ERROR_VARIABLE _vtk_wheel_error
    RESULT_VARIABLE _vtk_wheel_result
    OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(_vtk_wheel_result)
    message(FATAL_ERROR
      "This VTK SDK builds against the libraries of the PyPI wheel vtk==${_vtk_sdk_version}, "
      "and '${_vtk_wheel_python}' has no such wheel (pip install vtk==${_vtk_sdk_version} "
      "into it, set Python3_EXECUTABLE, or set VTK_WHEEL_LIBRARY_DIR): ${_vtk_wheel_error}")
  endif()
  list(GET _vtk_wheel_found 0 _vtk_wheel_version)
  list(GET _vtk_wheel_found 1 _vtk_wheel_dir)
  if(NOT _vtk_wheel_version STREQUAL _vtk_sdk_version)
    message(FATAL_ERROR
      "This VTK SDK is VTK ${_vtk_sdk_version}; '${_vtk_wheel_python}' has the vtk wheel "
      "${_vtk_wheel_version} (in ${_vtk_wheel_dir}). A module loads only into the VTK it was built "
      "against: install vtk==${_vtk_sdk_version}.")
  endif()
  # Not cached: an isolated build environment is another folder every time.
  set(VTK_WHEEL_LIBRARY_DIR "${_vtk_wheel_dir}")
  unset(_vtk_wheel_python CACHE)
  unset(_vtk_wheel_python)
endif()
