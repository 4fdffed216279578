// Image files: PNG and PFM output, RGBE (.hdr) and PFM input. Writers go
// through a temporary file renamed at the end, so that a failed write leaves
// no half-written output. Host-only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mmrtm/vecmath.h"

namespace mmrtm {

struct RGBImage {
  int width = 0, height = 0;
  std::vector<RGB> pixels;  // row 0 at the top
};

// Throws InputError naming the file and the problem.
RGBImage ReadRGBE(const std::string& path);
RGBImage ReadPFM(const std::string& path);
RGBImage ReadImageHDR(const std::string& path);  // by extension: .hdr or .pfm

// Throw std::runtime_error naming the file on failure; nothing is left behind.
void WritePFM(const std::string& path, const RGBImage& image);
void WritePNG(const std::string& path, int width, int height, int channels, const std::vector<uint8_t>& pixels);

// 8-bit PNG reading (for baseline images in tests). channels is 3 or 4 on return.
std::vector<uint8_t> ReadPNG(const std::string& path, int* width, int* height, int* channels);

}  // namespace mmrtm
