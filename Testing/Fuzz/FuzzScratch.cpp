#include "FuzzScratch.h"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace fs = std::filesystem;

namespace mmrtm::fuzz {
namespace {

void WriteFile(const std::string& path, const void* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error(path + ": cannot write the fuzz input");
  const bool ok = std::fwrite(data, 1, size, f) == size;
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error(path + ": cannot write the fuzz input");
}

std::string MakeScratchFolder() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/mmrtm-fuzz-XXXXXX";
  if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot make a scratch folder for the fuzz input");
  static std::string removeAtExit;
  removeAtExit = pattern;
  std::atexit([] {
    std::error_code ec;
    fs::remove_all(removeAtExit, ec);
  });
  // Detached data for .nhdr and .mhd headers: a ramp, raw and zlib-compressed.
  std::vector<uint8_t> ramp(4096);
  for (size_t i = 0; i < ramp.size(); ++i) ramp[i] = uint8_t(i * 7);
  WriteFile(pattern + "/data.raw", ramp.data(), ramp.size());
  uLongf packedSize = compressBound(ramp.size());
  std::vector<uint8_t> packed(packedSize);
  compress(packed.data(), &packedSize, ramp.data(), ramp.size());
  WriteFile(pattern + "/data.zraw", packed.data(), packedSize);
  return pattern;
}

}  // namespace

bool gVerbose = false;

void Outcome(const std::string& text) {
  if (gVerbose) std::printf("  -> %s\n", text.c_str());
}

const std::string& ScratchFolder() {
  static const std::string folder = MakeScratchFolder();
  return folder;
}

std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = ScratchFolder() + "/" + name;
  WriteFile(path, data, size);
  return path;
}

bool Contains(const uint8_t* data, size_t size, const char* text) {
  const size_t n = std::strlen(text);
  const auto same = [](uint8_t a, char b) { return std::tolower(a) == std::tolower((unsigned char)b); };
  return std::search(data, data + size, text, text + n, same) != data + size;
}

}  // namespace mmrtm::fuzz
