// VTK's own image formats: XML image data (.vti) and legacy structured
// points (.vtk).
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <vtkDataReader.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkStructuredPointsReader.h>
#include <vtkXMLImageDataReader.h>

namespace mmrtm
{

// Scientific data without anatomy: the coordinates are taken as LPS as they
// are. VTI files may carry a Direction matrix, which vtkImageData keeps.

namespace
{

// An attribute's value in an XML start tag ("" when absent).
std::string Attribute(const std::string& tag, const std::string& name)
{
  const std::regex pattern("\\s" + name + "=\"([^\"]*)\"");
  std::smatch m;
  return std::regex_search(tag, m, pattern) ? m[1].str() : std::string();
}

// vtkXMLDataParser dereferences null when the block header of compressed
// appended data is inconsistent (an array's offset one byte off: a fuzz
// finding). Reads every appended array's header first: for raw appended
// data (not base64) each header must lie within the data, its block count
// and sizes agree (block size above 0, the last block no larger), and its
// compressed blocks end within the file. Anything else is the reader's.
void CheckVtiAppendedData(const std::string& path)
{
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in)
    return;
  const uint64_t size = (uint64_t)in.tellg();
  in.seekg(0);
  // Only the XML before the appended data is read as text (at most 16 MiB
  // of it), then each array's header where it lies: a large file is not
  // read twice.
  std::string text;
  size_t appended = std::string::npos, appendedEnd = std::string::npos, marker = std::string::npos;
  std::vector<char> chunk(1 << 16);
  while (text.size() < (16u << 20))
  {
    in.read(chunk.data(), (std::streamsize)chunk.size());
    if (in.gcount() <= 0)
      break;
    text.append(chunk.data(), (size_t)in.gcount());
    if (appended == std::string::npos)
      appended = text.find("<AppendedData");
    if (appended != std::string::npos && appendedEnd == std::string::npos)
      appendedEnd = text.find('>', appended);
    if (appendedEnd != std::string::npos)
      marker = text.find('_', appendedEnd);
    if (marker != std::string::npos)
      break;
  }
  if (marker == std::string::npos)
    return; // no raw appended data (or its XML is huge): the reader's to judge
  if (Attribute(text.substr(appended, appendedEnd - appended + 1), "encoding") != "raw")
    return;
  const size_t vtkFile = text.find("<VTKFile");
  const std::string fileTag =
    vtkFile == std::string::npos ? "" : text.substr(vtkFile, text.find('>', vtkFile) - vtkFile + 1);
  const bool compressed = !Attribute(fileTag, "compressor").empty();
  const bool wide = Attribute(fileTag, "header_type") == "UInt64";
  const bool bigEndian = Attribute(fileTag, "byte_order") == "BigEndian";
  const uint64_t word = wide ? 8 : 4, data = marker + 1;
  // The header word at byte `at` of the file (within the file: checked by the caller).
  auto read = [&](uint64_t at)
  {
    unsigned char bytes[8] = {};
    in.clear();
    in.seekg((std::streamoff)at);
    in.read(reinterpret_cast<char*>(bytes), (std::streamsize)word);
    uint64_t v = 0;
    for (uint64_t i = 0; i < word; ++i)
      v = v << 8 | bytes[bigEndian ? i : word - 1 - i];
    return v;
  };
  // The most bytes an array can hold: the whole extent's points.
  double points = 0;
  {
    std::istringstream extent(Attribute(text.substr(0, appended), "WholeExtent"));
    double e[6];
    if (extent >> e[0] >> e[1] >> e[2] >> e[3] >> e[4] >> e[5])
      points = (e[1] - e[0] + 1) * (e[3] - e[2] + 1) * (e[5] - e[4] + 1);
  }
  auto typeSize = [](const std::string& type)
  {
    if (type == "Int8" || type == "UInt8")
      return 1;
    if (type == "Int16" || type == "UInt16")
      return 2;
    if (type == "Int32" || type == "UInt32" || type == "Float32")
      return 4;
    if (type == "Int64" || type == "UInt64" || type == "Float64")
      return 8;
    return 0; // strings, bits: not bounded here
  };
  const std::regex arrayTag("<DataArray[^>]*>");
  for (auto it = std::sregex_iterator(text.begin(), text.begin() + (std::ptrdiff_t)appended, arrayTag);
       it != std::sregex_iterator(); ++it)
  {
    const std::string tag = it->str();
    // vtkXMLReader reads any other word as appended (a fuzz finding).
    const std::string format = Attribute(tag, "format");
    if (format != "ascii" && format != "binary" && format != "appended")
      throw InputError(
        path + ": DataArray '" + Attribute(tag, "Name") + "' has format '" + format + "' (ascii, binary or appended)");
    if (format != "appended")
      continue;
    const std::string name = Attribute(tag, "Name"), offsetText = Attribute(tag, "offset");
    const std::string problem = path + ": appended data of array '" + name + "' (offset " + offsetText + "): ";
    char* end = nullptr;
    const unsigned long long offset = std::strtoull(offsetText.c_str(), &end, 10);
    if (offsetText.empty() || *end != '\0' || offset > size - data)
      throw InputError(problem + "the offset is past the end of the file");
    const uint64_t at = data + offset;
    if (!compressed)
    {
      if (size - at < word || read(at) > size - at - word)
        throw InputError(problem + "its size runs past the end of the file");
      continue;
    }
    if (size - at < 3 * word)
      throw InputError(problem + "the compression header runs past the end of the file");
    const uint64_t blocks = read(at), blockSize = read(at + word), lastSize = read(at + 2 * word);
    if (blocks > (size - at) / word - 3)
      throw InputError(problem + "the compression header runs past the end of the file");
    const std::string components = Attribute(tag, "NumberOfComponents");
    const double most = points * std::max(1, std::atoi(components.c_str())) * typeSize(Attribute(tag, "type"));
    const double bytes =
      blocks == 0 ? 0.0 : double(blocks - 1) * double(blockSize) + double(lastSize ? lastSize : blockSize);
    if (blocks == 0 || blockSize == 0 || lastSize > blockSize || (most > 0 && bytes > most))
      throw InputError(problem + "the compression header's blocks (" + std::to_string(blocks) + " of " +
        std::to_string(blockSize) + " bytes) do not fit the array (corrupt)");
    uint64_t total = 0;
    for (uint64_t b = 0; b < blocks; ++b)
      total += read(at + (3 + b) * word);
    if (total > size - at - (3 + blocks) * word)
      throw InputError(problem + "the compressed blocks run past the end of the file");
  }
}

} // namespace

void LoadVti(const std::string& path, HostVolume& out, const VolumeLoadOptions& options)
{
  vtkNew<vtkXMLImageDataReader> reader;
  if (!reader->CanReadFile(path.c_str()))
    throw InputError(path + ": not a VTK XML ImageData file");
  CheckVtiAppendedData(path);
  reader->SetFileName(path.c_str());
  vtkImageData* image = RunReader(reader, path, options.progress);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

namespace
{

// vtkStructuredPointsReader (VTK 9.1 to 9.6) dereferences the field data it
// failed to read: a FIELD section it cannot parse, or any keyword that only
// starts with "field", crashes it (a fuzz finding). Reads the dataset's
// keywords with the reader's own parser first, as ReadMeshSimple does, up
// to the point or cell data, and refuses such a file. Anything else wrong
// is left to the reader, which reports it.
void CheckDatasetFieldData(const std::string& path)
{
  vtkNew<vtkDataReader> reader;
  ReaderErrors errors(reader); // its messages are the real reader's to give
  if (!reader->OpenVTKFile(path.c_str()) || !reader->ReadHeader(path.c_str()))
    return;
  char word[256];
  if (!reader->ReadString(word) || std::strncmp(reader->LowerCase(word), "dataset", 7) != 0 ||
    !reader->ReadString(word))
  {
    reader->CloseVTKFile();
    return;
  }
  int integers[6];
  double reals[3];
  while (reader->ReadString(word))
  {
    reader->LowerCase(word);
    bool read = true;
    if (std::strncmp(word, "field", 5) == 0)
    {
      vtkFieldData* fields = reader->ReadFieldData();
      if (!fields)
      {
        reader->CloseVTKFile();
        throw InputError(path + ": a FIELD section VTK's legacy reader cannot read (keyword '" + word + "')");
      }
      fields->Delete();
    }
    else if (std::strncmp(word, "extent", 6) == 0)
    {
      for (int i = 0; i < 6 && read; ++i)
        read = reader->Read(integers + i) != 0;
    }
    else if (std::strncmp(word, "dimensions", 10) == 0)
    {
      for (int i = 0; i < 3 && read; ++i)
        read = reader->Read(integers + i) != 0;
    }
    else if (std::strncmp(word, "aspect_ratio", 12) == 0 || std::strncmp(word, "spacing", 7) == 0 ||
      std::strncmp(word, "origin", 6) == 0)
    {
      for (int i = 0; i < 3 && read; ++i)
        read = reader->Read(reals + i) != 0;
    }
    else
    {
      break; // point or cell data (where the dataset's keywords end), or an error the reader reports
    }
    if (!read)
      break;
  }
  reader->CloseVTKFile();
}

} // namespace

void LoadLegacyVtk(const std::string& path, HostVolume& out, const VolumeLoadOptions& options)
{
  vtkNew<vtkStructuredPointsReader> reader;
  reader->SetFileName(path.c_str());
  {
    ReaderErrors errors(reader);
    if (!reader->IsFileStructuredPoints())
    {
      errors.ThrowIfFailed(path);
      throw InputError(path + ": not a legacy VTK STRUCTURED_POINTS dataset");
    }
  }
  CheckDatasetFieldData(path);
  vtkImageData* image = RunReader(reader, path, options.progress);
  StoreImageVoxels(image, path, Rescale{}, out);
  out.indexToWorld = VtkImageIndexToWorld(image);
}

} // namespace mmrtm
