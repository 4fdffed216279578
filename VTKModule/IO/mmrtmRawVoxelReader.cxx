// Raw voxels read straight into the volume's own buffer: no reader array in
// between, no zero-filling, the file read by every thread at once.
#include "mmrtmVolumeLoaderInternal.h"

#include <algorithm>
#include <atomic>
#include <fstream>
#include <string>
#include <thread>

#include "parallel_for.h"

namespace mmrtm
{

namespace
{

// Large enough that a read is one system call's worth of copying, small
// enough that two threads share the work evenly and the bar moves.
constexpr int64_t kChunkBytes = int64_t(32) << 20;

bool MachineIsBigEndian()
{
  const uint16_t one = 1;
  return *reinterpret_cast<const uint8_t*>(&one) == 0;
}

void SwapBytes(uint8_t* bytes, int64_t count, int size)
{
  for (int64_t i = 0; i < count; ++i)
    std::reverse(bytes + i * size, bytes + (i + 1) * size);
}

} // namespace

void ReadRawVoxels(const RawVoxels& raw, HostVolume& out, const VolumeLoadOptions& options)
{
  const int size = VoxelTypeSize(raw.type);
  const int64_t total = raw.count * size;
  CheckMemoryAvailable(raw.path, (double)total, std::to_string(raw.count) + " voxels");
  // new[] leaves the bytes unset (a vector would zero them: one more pass
  // over the whole volume, and every page touched twice).
  std::shared_ptr<uint8_t> storage(new uint8_t[std::max<int64_t>(total, 1)], std::default_delete<uint8_t[]>());
  const bool swap = size > 1 && raw.bigEndian != MachineIsBigEndian();

  const int64_t chunks = (total + kChunkBytes - 1) / kChunkBytes;
  std::atomic<int64_t> nextChunk{ 0 }, bytesRead{ 0 };
  enum Failure
  {
    kNone,
    kCannotOpen,
    kShort
  };
  std::atomic<int> failure{ kNone };
  const int threads = (int)std::clamp<int64_t>(std::thread::hardware_concurrency(), 1, std::max<int64_t>(chunks, 1));
  RunWorkers(threads,
    [&](int worker)
    {
      std::ifstream in(raw.file, std::ios::binary);
      if (!in)
      {
        failure = kCannotOpen;
        return;
      }
      for (int64_t c = nextChunk++; c < chunks && failure == kNone; c = nextChunk++)
      {
        const int64_t begin = c * kChunkBytes, bytes = std::min(kChunkBytes, total - begin);
        in.seekg((std::streamoff)(raw.offset + begin));
        in.read(reinterpret_cast<char*>(storage.get() + begin), (std::streamsize)bytes);
        if (in.gcount() != bytes)
        {
          failure = kShort;
          return;
        }
        if (swap)
          SwapBytes(storage.get() + begin, bytes / size, size);
        bytesRead += bytes;
        if (worker == 0 && options.progress)
          options.progress((double)bytesRead / (double)total);
      }
    });
  const std::string file = raw.file == raw.path ? "the file" : "its data file '" + raw.file + "'";
  if (failure == kCannotOpen)
    throw InputError(raw.path + ": " + file + " cannot be opened");
  if (failure == kShort)
    throw InputError(raw.path + ": " + file + " ends before its " + std::to_string(total) +
      " bytes of voxels (from byte " + std::to_string(raw.offset) + "): truncated, or changed while it was read");
  if (options.progress)
    options.progress(1.0);
  out.type = raw.type;
  out.voxels = VoxelBuffer::Adopt(storage.get(), (size_t)total, storage);
}

} // namespace mmrtm
