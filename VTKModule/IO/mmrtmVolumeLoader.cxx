// LoadVolume and DefaultVolumePath (see mmrtmVolumeLoader.h for the
// contract): LoadVolume picks a format's loader by the path's extension, or
// the DICOM loader for a folder. Each format's loader has its own file.
#include "mmrtmVolumeLoader.h"

#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <system_error>

#include "mmrtmVolumeLoaderInternal.h"

namespace fs = std::filesystem;

namespace mmrtm
{
namespace
{

bool EndsWith(const std::string& s, const std::string& suffix)
{
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The extension that selects the format, lower-case, with ".nii.gz" kept whole.
std::string VolumeExtension(const std::string& path)
{
  const std::string file = ToLower(fs::path(path).filename().string());
  if (EndsWith(file, ".nii.gz"))
    return ".nii.gz";
  return fs::path(file).extension().string();
}

using FileLoader = void (*)(const std::string&, HostVolume&, const VolumeLoadOptions&);

struct FormatEntry
{
  const char* extension;
  FileLoader load;
};

constexpr FormatEntry kFormats[] = {
  { ".nrrd", LoadNrrd },
  { ".nhdr", LoadNrrd },
  { ".nii", LoadNifti },
  { ".nii.gz", LoadNifti },
  { ".mha", LoadMetaImage },
  { ".mhd", LoadMetaImage },
  { ".vti", LoadVti },
  { ".vtk", LoadLegacyVtk },
  { ".inv3", LoadInVesalius },
};

void LoadVolumeFile(const std::string& path, HostVolume& out, const VolumeLoadOptions& options)
{
  const std::string ext = VolumeExtension(path);
  for (const FormatEntry& f : kFormats)
    if (ext == f.extension)
      return f.load(path, out, options);
  std::string known;
  for (const FormatEntry& f : kFormats)
    known += std::string(known.empty() ? "" : " ") + f.extension;
  throw InputError(path + ": unknown volume format '" + ext + "' (known: " + known + ", or a DICOM folder)");
}

} // namespace

HostVolume LoadVolume(const std::string& path, const std::string& name, Interpolation interpolation)
{
  VolumeLoadOptions options;
  options.interpolation = interpolation;
  return LoadVolume(path, name, options);
}

HostVolume LoadVolume(const std::string& path, const std::string& name, const VolumeLoadOptions& options)
{
  if (path.empty())
    throw InputError("no volume path given");
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status))
    throw InputError(path + ": no such file or folder");

  HostVolume volume;
  volume.name = name;
  volume.source = path;
  volume.interpolation = options.interpolation;
  try
  {
    if (fs::is_directory(status))
      LoadDicomFolder(path, volume, options);
    else
      LoadVolumeFile(path, volume, options);
  }
  catch (const InputError&)
  {
    throw;
  }
  catch (const std::bad_alloc&)
  {
    throw InputError(path + ": not enough memory for the volume (is the header corrupt?)");
  }
  catch (const std::exception& e)
  {
    throw InputError(path + ": " + e.what());
  }
  volume.ReplaceNanVoxels(); // the caller warns (nanVoxelsReplaced)
  volume.Validate();
  return volume;
}

std::string DefaultVolumePath()
{
  return "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";
}

} // namespace mmrtm
