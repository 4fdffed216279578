// PRIVATE to VTKModule/IO: what the volume loader's files share (helpers,
// voxel conversion, VTK reader glue, one loader per format). Not installed and
// not part of mmrtm_volume_io's interface: include it only from the .cxx files
// in this folder. Everyone else uses mmrtmVolumeLoader.h. No VTK header here.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "host_volume.h"
#include "mmrtmVolumeLoader.h"

class vtkAlgorithm;
class vtkDataArray;
class vtkImageData;

namespace mmrtm
{

using Vec3d = std::array<double, 3>;
using Mat3d = std::array<double, 9>; // row-major; column c is the direction of index axis c

inline constexpr Mat3d kIdentity3 = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };

// ---------------------------------------------------------------------------
// Small helpers (mmrtmLoaderUtilities.cxx)
// ---------------------------------------------------------------------------

std::string ToLower(std::string s);
std::string Trim(const std::string& s);

// Whitespace-separated numbers; stops at the first token that is not one.
std::vector<double> ParseNumbers(const std::string& text);

// A whole word as an integer within int's range, as the readers (VTK,
// metaio) parse these fields; nullopt for anything else ("2t", "1-6",
// "8e72"): those readers take such words as numbers anyway and crash.
std::optional<long long> IntegerWord(const std::string& word);

// Every word of a header field (sizes, DimSize) as a positive integer
// within int's range; throws InputError "PATH: WHAT must be positive
// integers: VALUE" otherwise.
std::vector<int64_t> PositiveIntegers(const std::string& path, const std::string& what, const std::string& value);

Vec3d Cross(const Vec3d& a, const Vec3d& b);
double Dot(const Vec3d& a, const Vec3d& b);

[[noreturn]] void ThrowComponents(const std::string& path, int64_t components);

// The uncompressed DICOM transfer syntaxes (implicit/explicit little endian,
// explicit big endian): pixel data of a known size, which every reader decodes.
bool IsUncompressedTransferSyntax(const std::string& uid);

// Walks the data elements of a DICOM file and checks each stated length
// against the bytes left in the file (mmrtmDicomElementCheck.cxx): "" when
// they fit (or the file is not one the walk judges), else the problem, to
// be reported before GDCM allocates a corrupt length.
std::string CheckDicomElementLengths(const std::string& file);

// ---------------------------------------------------------------------------
// Voxel conversion (mmrtmLoaderUtilities.cxx)
// ---------------------------------------------------------------------------

// Voxel types as files store them, before the choice of a HostVolume type.
enum class SourceType
{
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Int64,
  UInt64,
  Float32,
  Float64
};

// value = stored * slope + intercept (NIfTI scl_*, DICOM rescale).
struct Rescale
{
  double slope = 1.0, intercept = 0.0;
  bool IsIdentity() const { return slope == 1.0 && intercept == 0.0; }
};

// The voxel type the tracer samples `t` as, when it stores it as it is
// (DESIGN.md rule 3: uint8, int16, uint16, float32); nullopt otherwise.
std::optional<VoxelType> NativeVoxelType(SourceType t);

// Stores `count` voxels of `type` into `out` (type and voxels), applying the
// rescale and choosing the voxel type by the rules in mmrtmVolumeLoader.h.
void StoreVoxels(const void* data, SourceType type, int64_t count, Rescale rescale, HostVolume& out);

// The range of a set of values and whether all are integers (NaN and
// infinities are not).
struct ValueStats
{
  bool allIntegers = true;
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void Add(const ValueStats& other);
};
ValueStats ScanFloatValues(const float* values, int64_t count);

// The smallest integer type that holds every value exactly, else float32.
// int16 is preferred over uint16 when both fit: CT and most medical data are signed.
VoxelType SmallestExactType(const ValueStats& s);

// Slices decoded one at a time (as float: a DICOM slice after its rescale)
// gathered into a volume of the smallest voxel type that holds every value
// put so far exactly (SmallestExactType), so that no float volume is held
// on the way (mmrtmSliceStack.cxx). A slice that needs a wider type widens
// the slices stored before it, once per type.
class SliceStack
{
public:
  SliceStack(int64_t sliceVoxels, int slices);
  // Slice `index`'s values; `stats` as ScanFloatValues gives them.
  void Put(int index, const float* values, const ValueStats& stats);
  // Moves the volume into `out` (type and voxels). Slices never put are 0.
  void MoveInto(HostVolume& out);

private:
  void Widen(VoxelType type);

  int64_t sliceVoxels_;
  int slices_;
  ValueStats stats_;
  VoxelType type_ = VoxelType::UInt8;
  std::vector<uint8_t> voxels_;
};

// Throws InputError naming `path` when `bytes` (the voxels about to be
// allocated, described by `what`) exceed the memory this machine has
// available, before anything is allocated.
void CheckMemoryAvailable(const std::string& path, double bytes, const std::string& what);

// How voxel data is stored in a file, for CheckDeclaredVoxelBytes.
enum class DataEncoding
{
  Raw,
  Compressed,
  Text
};

// Checks a header's promise of `declaredBytes` of voxels (`count` values)
// against the `fileBytes` that are to hold them, before any reader allocates
// for it: raw data needs every byte; zlib/gzip data can shrink at most
// 1032:1; text needs at least one character per value. Then
// CheckMemoryAvailable. Throws InputError naming `path`: a truncated file or
// a corrupt header ("sizes" that promise terabytes) is an error, not an
// allocation attempt.
// `dataFile` names a detached data file in the message ("" for the file itself).
void CheckDeclaredVoxelBytes(const std::string& path, double declaredBytes, double count, double fileBytes,
  DataEncoding encoding, const std::string& dataFile = "");

// A printf format that names the files of a series (NRRD's `data file:
// <format> ...`, MetaImage's `ElementDataFile = <pattern> ...`): both
// readers pass it to a printf with one integer, so it must hold exactly one
// integer conversion (%d, %03d, %i) and no other (a %s or %n would read or
// write memory). Throws InputError naming `path` and `what`.
void CheckFileNamePattern(const std::string& path, const std::string& what, const std::string& pattern);

// Sends a warning to options.warn, or to stderr.
void Warn(const VolumeLoadOptions& options, const std::string& message);

// Reverses, in place, the order of the runs of `runVoxels` voxels within each
// block of `runsPerBlock` runs. With runs of one row (nx voxels) and blocks of
// one slice this flips y; with runs of one slice and one block it flips z.
void ReverseRuns(HostVolume& v, int64_t runVoxels, int64_t runsPerBlock);

// ---------------------------------------------------------------------------
// Raw voxels (mmrtmRawVoxelReader.cxx)
// ---------------------------------------------------------------------------

// Voxels stored uncompressed, x fastest, in one file.
struct RawVoxels
{
  std::string path;                  // the input, named in messages
  std::string file;                  // the file that holds the voxels (`path` when attached)
  uint64_t offset = 0;               // where they start in `file`
  int64_t count = 0;                 // how many
  VoxelType type = VoxelType::UInt8; // a type the tracer samples natively
  bool bigEndian = false;
};

// Reads the voxels straight into `out` (type and voxels: a buffer of its
// own, filled by all threads at once, bytes swapped to this machine's
// order), reporting options.progress. Throws InputError naming the input
// when the file cannot be opened or ends early (nothing is kept then).
void ReadRawVoxels(const RawVoxels& raw, HostVolume& out, const VolumeLoadOptions& options);

// ---------------------------------------------------------------------------
// VTK glue (mmrtmVtkReaderGlue.cxx)
// ---------------------------------------------------------------------------

// Watches a reader, its executive and the output window for errors while it
// lives. The output window is process-wide: loading is meant for one thread.
class ReaderErrors
{
public:
  explicit ReaderErrors(vtkAlgorithm* reader);
  ~ReaderErrors();
  ReaderErrors(const ReaderErrors&) = delete;
  ReaderErrors& operator=(const ReaderErrors&) = delete;

  // Throws InputError naming `path` if the reader reported an error.
  void ThrowIfFailed(const std::string& path) const;

private:
  struct Watch; // the observers and the output window (VTK types): defined in the .cxx
  std::unique_ptr<Watch> watch_;
};

// Runs a reader and returns its image, which the reader owns, passing the
// reader's progress events to `progress`. Throws InputError when the reader
// fails or produces no voxels.
vtkImageData* RunReader(
  vtkAlgorithm* reader, const std::string& path, const std::function<void(double)>& progress = {});

// The point-data array that holds the voxels: the active scalars, else the
// only point array (VTI files need not mark their scalars active).
vtkDataArray* VoxelArray(vtkImageData* image, const std::string& path);

// The SourceType of a VTK scalar type (VTK_SHORT, ...); throws InputError
// naming `path` for a type it cannot hold.
SourceType SourceTypeOfVtk(int vtkType, const std::string& path);

// Who holds a VTK array whose voxels a HostVolume reads in place.
enum class ArrayHolder
{
  Loader, // the loader's own reader, which goes when the loader returns: the volume may write into it
  Caller  // an application's (the mapper's input): never written; a write copies first
};

// Puts the `count` values of `a` (contiguous, x fastest) into `out` (type
// and voxels). Values of a type the tracer samples natively that need no
// rescale are read in place: `out.voxels` borrows the array's memory and
// holds a reference to the array (mmrtmArrayVoxels.cxx). Any other type, a
// rescale or an array without VTK's standard memory layout is converted
// into a buffer of the volume's own (StoreVoxels). `path` names the input in
// messages.
void StoreArrayVoxels(
  vtkDataArray* a, int64_t count, Rescale rescale, ArrayHolder holder, HostVolume& out, const std::string& path);

// A single-component image's voxels in `out` (dims, type, voxels), read in
// place where StoreArrayVoxels can.
void StoreImageVoxels(vtkImageData* image, const std::string& path, Rescale rescale, HostVolume& out);

// x_world = origin + D * (spacing * index), with index 0 at the first stored
// voxel.
Affine3 VtkImageIndexToWorld(vtkImageData* image);

// ---------------------------------------------------------------------------
// One loader per format, each in its own file. Each fills `out`'s dims, type,
// voxels and indexToWorld (LoadVolume sets the rest); bad input throws InputError.
// ---------------------------------------------------------------------------

void LoadNrrd(const std::string& path, HostVolume& out, const VolumeLoadOptions& options);  // mmrtmNrrdLoader.cxx
void LoadNifti(const std::string& path, HostVolume& out, const VolumeLoadOptions& options); // mmrtmNiftiLoader.cxx
void LoadMetaImage(
  const std::string& path, HostVolume& out, const VolumeLoadOptions& options);            // mmrtmMetaImageLoader.cxx
void LoadVti(const std::string& path, HostVolume& out, const VolumeLoadOptions& options); // mmrtmVtkImageLoader.cxx
void LoadLegacyVtk(
  const std::string& path, HostVolume& out, const VolumeLoadOptions& options); // mmrtmVtkImageLoader.cxx
// mmrtmItkDicomLoader.cxx with ITK, else mmrtmDicomLoader.cxx (VTK)
void LoadDicomFolder(const std::string& folder, HostVolume& out, const VolumeLoadOptions& options);
void LoadInVesalius(
  const std::string& path, HostVolume& out, const VolumeLoadOptions& options); // mmrtmInVesaliusLoader.cxx

} // namespace mmrtm
