// libFuzzer target: one format of mmrtm::LoadVolume (VTKModule/IO). Built
// once per format, MMRTM_FUZZ_FORMAT naming it: "nrrd" (.nrrd, or .nhdr
// when the header names a data file), "nifti" (.nii, .nii.gz when gzip),
// "metaimage" (.mha, .mhd when the data is in a file of its own),
// "vtk-image" (.vti for XML, else legacy .vtk), "invesalius" (.inv3),
// "dicom" (one file in a folder, read as a series through ITK/GDCM).
//
// What counts as a finding: anything but a volume or an InputError (a
// crash, another exception, a sanitizer report, a hang, an allocation over
// the fuzzer's limit), and a volume whose geometry or values are unusable
// (LoadVolume promises to reject those with an InputError).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "FuzzScratch.h"
#include "mmrtmVolumeLoader.h"

#ifndef MMRTM_FUZZ_FORMAT
#error "MMRTM_FUZZ_FORMAT names the format this target fuzzes"
#endif

namespace {

using mmrtm::fuzz::Contains;

// The path the input is written to: the extension that picks the loader.
std::string InputPath(const std::string& format, const uint8_t* data, size_t size) {
  std::string name;
  if (format == "nrrd")
    name = Contains(data, size, "data file:") || Contains(data, size, "datafile:") ? "input.nhdr" : "input.nrrd";
  else if (format == "nifti")
    name = size >= 2 && data[0] == 0x1f && data[1] == 0x8b ? "input.nii.gz" : "input.nii";
  else if (format == "metaimage")
    name = Contains(data, size, "ElementDataFile") && !Contains(data, size, "LOCAL") ? "input.mhd" : "input.mha";
  else if (format == "vtk-image")
    name = Contains(data, size, "<VTKFile") ? "input.vti" : "input.vtk";
  else if (format == "invesalius")
    name = "input.inv3";
  else if (format == "dicom") {
    std::filesystem::create_directories(mmrtm::fuzz::ScratchFolder() + "/series");
    mmrtm::fuzz::WriteScratchFile("series/slice.dcm", data, size);
    return mmrtm::fuzz::ScratchFolder() + "/series";
  } else {
    std::abort();  // a target built with an unknown format
  }
  return mmrtm::fuzz::WriteScratchFile(name, data, size);
}

bool Finite(const mmrtm::Affine3& a) {
  for (const auto& row : a.m)
    for (float v : row)
      if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = InputPath(MMRTM_FUZZ_FORMAT, data, size);
  mmrtm::VolumeLoadOptions options;
  options.warn = [](const std::string&) {};  // warnings are expected on odd input
  try {
    const mmrtm::HostVolume volume = mmrtm::LoadVolume(path, "scalars", options);
    // What LoadVolume promises of a volume it returns.
    const mmrtm::VolumeView view = volume.View();
    if (!Finite(volume.indexToWorld) || !Finite(view.worldToIndex)) std::abort();
    const auto range = volume.ValueRange();
    if (!std::isfinite(range[0]) || !std::isfinite(range[1])) std::abort();
    mmrtm::fuzz::Outcome("a volume of " + std::to_string(volume.dims[0]) + " x " + std::to_string(volume.dims[1]) +
                         " x " + std::to_string(volume.dims[2]) + " voxels");
  } catch (const mmrtm::InputError& e) {
    mmrtm::fuzz::Outcome(e.what());  // a clear error for bad input: what the loader should do
  }
  return 0;
}
