// VTK glue the volume loader's format files share: catching the errors VTK
// readers report (ReaderErrors, RunReader), taking over the voxels of a
// vtkImageData and reading a vtkImageData's index-to-world geometry.
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <cctype>
#include <functional>
#include <memory>
#include <string>

#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkInformation.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkType.h>

namespace mmrtm
{
namespace
{

// VTK error text looks like "ERROR: In file.cxx, line N\nvtkFoo (0x...): what\n\n";
// keep "what", which is the part a user can act on.
std::string CleanVtkMessage(const std::string& raw)
{
  std::string msg = raw;
  const size_t newline = msg.find('\n');
  if (msg.rfind("ERROR:", 0) == 0 || msg.rfind("Warning:", 0) == 0 || msg.rfind("Generic Warning:", 0) == 0)
  {
    if (newline != std::string::npos)
      msg = msg.substr(newline + 1);
    const size_t tag = msg.find("): ");
    if (tag != std::string::npos)
      msg = msg.substr(tag + 3);
  }
  // Some messages quote the file's bytes: keep them printable and short.
  for (char& c : msg)
    if (!std::isprint((unsigned char)c) && c != '\n')
      c = '?';
  msg = Trim(msg);
  if (msg.size() > 300)
    msg = msg.substr(0, 300) + "...";
  return msg;
}

// vtkErrorCode's own names live in VTK::CommonMisc, which the project does
// not link; these are the codes readers set.
std::string DescribeVtkErrorCode(unsigned long code)
{
  switch (code)
  {
    case vtkErrorCode::FileNotFoundError:
      return "file not found";
    case vtkErrorCode::CannotOpenFileError:
      return "cannot open the file";
    case vtkErrorCode::UnrecognizedFileTypeError:
      return "unrecognized file type";
    case vtkErrorCode::PrematureEndOfFileError:
      return "premature end of file (truncated?)";
    case vtkErrorCode::FileFormatError:
      return "file format error";
    case vtkErrorCode::NoFileNameError:
      return "no file name";
    default:
      return "VTK reader error " + std::to_string(code);
  }
}

// Collects the first error a VTK object reports, and keeps errors and
// warnings off the console (the loader reports them as InputError instead).
class VtkErrorCatcher : public vtkCommand
{
public:
  static VtkErrorCatcher* New() { return new VtkErrorCatcher; }
  void Execute(vtkObject*, unsigned long event, void* callData) override
  {
    if (event == vtkCommand::ErrorEvent && message.empty())
      message = callData ? CleanVtkMessage(static_cast<const char*>(callData)) : "unknown VTK error";
  }
  std::string message;
};

// Records the first error or warning that reaches the output window.
// Readers report some failures only there, from helper functions that have
// no object to observe: vtkImageReader's "File operation failed" on a short
// raw file, vtkDataReader's "Error reading binary data!", the XML parser's
// syntax errors.
class CapturingOutputWindow : public vtkOutputWindow
{
public:
  static CapturingOutputWindow* New()
  {
    auto* window = new CapturingOutputWindow;
    window->InitializeObjectBase();
    return window;
  }
  vtkTypeMacro(CapturingOutputWindow, vtkOutputWindow)
  void DisplayErrorText(const char* text) override { Record(text); }
  void DisplayWarningText(const char* text) override { Record(text); }
  void DisplayGenericWarningText(const char* text) override { Record(text); }
  std::string message;

private:
  void Record(const char* text)
  {
    if (message.empty())
      message = text ? CleanVtkMessage(text) : "unknown VTK error";
  }
};

} // namespace

// What a ReaderErrors watches with, kept here so that the shared header
// needs no VTK header.
struct ReaderErrors::Watch
{
  explicit Watch(vtkAlgorithm* r)
    : reader(r)
    , previousWindow(vtkOutputWindow::GetInstance())
  {
  }
  vtkAlgorithm* reader;
  vtkSmartPointer<vtkOutputWindow> previousWindow;
  vtkNew<CapturingOutputWindow> window;
  vtkNew<VtkErrorCatcher> readerCatcher, executiveCatcher;
  unsigned long readerTags[2] = { 0, 0 }, executiveTag = 0;
};

ReaderErrors::ReaderErrors(vtkAlgorithm* reader)
  : watch_(std::make_unique<Watch>(reader))
{
  Watch& w = *watch_;
  w.readerTags[0] = reader->AddObserver(vtkCommand::ErrorEvent, w.readerCatcher);
  w.readerTags[1] = reader->AddObserver(vtkCommand::WarningEvent, w.readerCatcher);
  w.executiveTag = reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, w.executiveCatcher);
  vtkOutputWindow::SetInstance(w.window);
}

ReaderErrors::~ReaderErrors()
{
  Watch& w = *watch_;
  vtkOutputWindow::SetInstance(w.previousWindow);
  w.reader->RemoveObserver(w.readerTags[0]);
  w.reader->RemoveObserver(w.readerTags[1]);
  w.reader->GetExecutive()->RemoveObserver(w.executiveTag);
}

void ReaderErrors::ThrowIfFailed(const std::string& path) const
{
  const Watch& w = *watch_;
  if (!w.readerCatcher->message.empty())
    throw InputError(path + ": cannot read: " + w.readerCatcher->message);
  if (!w.window->message.empty())
    throw InputError(path + ": cannot read: " + w.window->message);
  if (w.reader->GetErrorCode() != vtkErrorCode::NoError)
    throw InputError(path + ": cannot read: " + DescribeVtkErrorCode(w.reader->GetErrorCode()));
  // The executive's own messages are long pipeline dumps: report only the failure.
  if (!w.executiveCatcher->message.empty())
    throw InputError(path + ": cannot read (the reader failed)");
}

vtkImageData* RunReader(vtkAlgorithm* reader, const std::string& path, const std::function<void(double)>& progress)
{
  ReaderErrors errors(reader);
  // The header first: a volume too large for this machine is refused before
  // the reader allocates it (counted as its buffer and a converted copy,
  // which live together where the voxels need converting).
  reader->UpdateInformation();
  errors.ThrowIfFailed(path);
  if (vtkInformation* info = reader->GetOutputInformation(0);
      info && info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    int e[6];
    info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), e);
    const double nx = e[1] - e[0] + 1.0, ny = e[3] - e[2] + 1.0, nz = e[5] - e[4] + 1.0;
    const double bytes = nx * ny * nz * vtkDataArray::GetDataTypeSize(vtkImageData::GetScalarType(info)) *
      std::max(1, vtkImageData::GetNumberOfScalarComponents(info));
    CheckMemoryAvailable(path, 2.0 * bytes,
      "reading " + std::to_string((long long)nx) + " x " + std::to_string((long long)ny) + " x " +
        std::to_string((long long)nz) + " voxels");
  }
  vtkNew<vtkCallbackCommand> onProgress;
  if (progress)
  {
    onProgress->SetClientData(const_cast<std::function<void(double)>*>(&progress));
    onProgress->SetCallback([](vtkObject*, unsigned long, void* client, void* fraction)
      { (*static_cast<const std::function<void(double)>*>(client))(*static_cast<double*>(fraction)); });
    reader->AddObserver(vtkCommand::ProgressEvent, onProgress);
  }
  reader->Update();
  reader->RemoveObserver(onProgress);
  errors.ThrowIfFailed(path);
  vtkImageData* image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
  if (!image)
    throw InputError(path + ": cannot read: the reader produced no image");
  const int* d = image->GetDimensions();
  if (d[0] <= 0 || d[1] <= 0 || d[2] <= 0 || image->GetNumberOfPoints() == 0)
    throw InputError(path + ": empty volume (no voxels)");
  return image;
}

vtkDataArray* VoxelArray(vtkImageData* image, const std::string& path)
{
  vtkPointData* pd = image->GetPointData();
  vtkDataArray* a = pd->GetScalars();
  if (!a && pd->GetNumberOfArrays() >= 1)
    a = pd->GetArray(0);
  if (!a)
    throw InputError(path + ": holds no scalar point data");
  return a;
}

SourceType SourceTypeOfVtk(int vtkType, const std::string& path)
{
  switch (vtkType)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
      return SourceType::Int8;
    case VTK_UNSIGNED_CHAR:
      return SourceType::UInt8;
    case VTK_SHORT:
      return SourceType::Int16;
    case VTK_UNSIGNED_SHORT:
      return SourceType::UInt16;
    case VTK_INT:
      return SourceType::Int32;
    case VTK_UNSIGNED_INT:
      return SourceType::UInt32;
    case VTK_LONG:
      return sizeof(long) == 8 ? SourceType::Int64 : SourceType::Int32;
    case VTK_UNSIGNED_LONG:
      return sizeof(long) == 8 ? SourceType::UInt64 : SourceType::UInt32;
    case VTK_LONG_LONG:
    case VTK_ID_TYPE:
      return SourceType::Int64;
    case VTK_UNSIGNED_LONG_LONG:
      return SourceType::UInt64;
    case VTK_FLOAT:
      return SourceType::Float32;
    case VTK_DOUBLE:
      return SourceType::Float64;
    default:
      throw InputError(path + ": unsupported voxel type " + vtkImageScalarTypeNameMacro(vtkType));
  }
}

void StoreImageVoxels(vtkImageData* image, const std::string& path, Rescale rescale, HostVolume& out)
{
  vtkDataArray* a = VoxelArray(image, path);
  if (a->GetNumberOfComponents() != 1)
    ThrowComponents(path, a->GetNumberOfComponents());
  const int* d = image->GetDimensions();
  out.dims = { d[0], d[1], d[2] };
  if (a->GetNumberOfTuples() != out.VoxelCount())
    throw InputError(path + ": holds " + std::to_string(a->GetNumberOfTuples()) + " voxels, expected " +
      std::to_string(out.VoxelCount()) + " (truncated or corrupt?)");
  StoreArrayVoxels(a, out.VoxelCount(), rescale, ArrayHolder::Loader, out, path);
}

// VTK images may start at a non-zero extent; fold that into the origin.
Affine3 VtkImageIndexToWorld(vtkImageData* image)
{
  const double* o = image->GetOrigin();
  const double* s = image->GetSpacing();
  const int* e = image->GetExtent();
  Mat3d d = kIdentity3;
  if (vtkMatrix3x3* m = image->GetDirectionMatrix())
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        d[3 * r + c] = m->GetElement(r, c);
  Vec3d origin;
  for (int r = 0; r < 3; ++r)
  {
    origin[r] = o[r];
    for (int c = 0; c < 3; ++c)
      origin[r] += d[3 * r + c] * s[c] * e[2 * c];
  }
  return IndexToWorld(origin, { s[0], s[1], s[2] }, d);
}

} // namespace mmrtm
