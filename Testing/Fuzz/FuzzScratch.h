// The parsers under fuzzing read files, not buffers (every user's bytes
// reach them as a path), so each fuzz target writes its input into a
// private scratch folder first. One folder per process, removed at exit;
// it also holds the detached data files that headers may name.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace mmrtm::fuzz {

// The scratch folder (created on first use under $TMPDIR, removed at exit).
// It holds "data.raw" (4096 bytes, a ramp) and "data.zraw" (the same,
// zlib-compressed) for headers that name a detached data file.
const std::string& ScratchFolder();

// Writes `size` bytes to ScratchFolder()/name and returns the path.
std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size);

// Says what became of an input (a loaded volume, or the error message):
// printed when the inputs are replayed by FuzzReplayMain (which sets
// gVerbose), silent under libFuzzer.
extern bool gVerbose;
void Outcome(const std::string& text);

// Whether `size` bytes at `data` contain `text` (case-insensitive).
bool Contains(const uint8_t* data, size_t size, const char* text);

}  // namespace mmrtm::fuzz
