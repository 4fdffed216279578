#include "image_io.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "host_volume.h"

namespace mmrtm {

namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower((unsigned char)s[s.size() - suffix.size() + i]) != suffix[i]) return false;
  return true;
}

// Writes through `path + ".partial"` and renames, so no half-written file remains.
template <typename WriteFn>
void WriteAtomically(const std::string& path, WriteFn write) {
  const std::string tmp = path + ".partial";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error(path + ": cannot open for writing (" + std::strerror(errno) + ")");
  bool ok = false;
  try {
    ok = write(f);
  } catch (...) {
    std::fclose(f);
    std::remove(tmp.c_str());
    throw;
  }
  ok = (std::fclose(f) == 0) && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": write failed");
  }
}

// The bytes from the stream's position to the end of the file.
double BytesLeft(std::ifstream& in) {
  const std::streampos here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streampos end = in.tellg();
  in.seekg(here);
  return here < 0 || end < here ? 0.0 : double(end - here);
}

// A header's image size against the bytes that can hold it (at least
// `minBytes` of them), before the pixels are allocated: a corrupt header
// ("-Y 1000000 +X 1000000") is an error, not a 12 TB allocation.
void CheckImageSize(const std::string& path, int w, int h, double minBytes, double bytesLeft) {
  if (w > 65536 || h > 65536)
    throw InputError(path + ": " + std::to_string(w) + " x " + std::to_string(h) +
                     " pixels is beyond the 65536 x 65536 this reader takes");
  if (minBytes > bytesLeft)
    throw InputError(path + ": the header promises " + std::to_string(w) + " x " + std::to_string(h) +
                     " pixels but the file holds only " + std::to_string((long long)bytesLeft) +
                     " bytes of pixel data (truncated, or a corrupt header)");
}

}  // namespace

RGBImage ReadPFM(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::string magic;
  int w = 0, h = 0;
  double scale = 0;
  in >> magic >> w >> h >> scale;
  in.get();  // the single whitespace before the raster
  if (!in || (magic != "PF" && magic != "Pf") || w <= 0 || h <= 0 || scale == 0)
    throw InputError(path + ": not a PFM file (bad header)");
  const int channels = magic == "PF" ? 3 : 1;
  CheckImageSize(path, w, h, 4.0 * channels * w * h, BytesLeft(in));
  std::vector<float> raster((size_t)w * h * channels);
  in.read(reinterpret_cast<char*>(raster.data()), (std::streamsize)(raster.size() * sizeof(float)));
  if (!in) throw InputError(path + ": truncated PFM raster");
  const bool bigEndian = scale > 0;
  if (bigEndian)
    for (float& v : raster) {
      uint32_t u;
      std::memcpy(&u, &v, 4);
      u = __builtin_bswap32(u);
      std::memcpy(&v, &u, 4);
    }
  RGBImage image{w, h, std::vector<RGB>((size_t)w * h)};
  for (int y = 0; y < h; ++y)  // PFM rows run bottom to top
    for (int x = 0; x < w; ++x) {
      const float* p = &raster[((size_t)(h - 1 - y) * w + x) * channels];
      image.pixels[(size_t)y * w + x] = channels == 3 ? RGB(p[0], p[1], p[2]) : RGB(p[0]);
    }
  return image;
}

RGBImage ReadRGBE(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::string line;
  std::getline(in, line);
  if (line.rfind("#?", 0) != 0) throw InputError(path + ": not a Radiance .hdr file");
  bool rgbe = false;
  while (std::getline(in, line) && !line.empty())
    if (line == "FORMAT=32-bit_rle_rgbe") rgbe = true;
  if (!rgbe) throw InputError(path + ": only the 32-bit_rle_rgbe format is supported");
  std::string ylabel, xlabel;
  int w = 0, h = 0;
  {
    std::getline(in, line);
    std::istringstream res(line);
    res >> ylabel >> h >> xlabel >> w;
    if (ylabel != "-Y" || xlabel != "+X" || w <= 0 || h <= 0)
      throw InputError(path + ": unsupported resolution line '" + line + "' (need -Y H +X W)");
  }
  // A row is 4 bytes a pixel, or (run-length encoded, 8 pixels wide or more)
  // at least 4 bytes and 2 a run of up to 127 pixels per component.
  const double rowBytes = w < 8 ? 4.0 * w : std::min(4.0 * w, 4.0 + 8.0 * std::ceil(w / 127.0));
  CheckImageSize(path, w, h, h * rowBytes, BytesLeft(in));
  RGBImage image{w, h, std::vector<RGB>((size_t)w * h)};
  std::vector<uint8_t> scan((size_t)w * 4);
  auto byte = [&]() {
    int c = in.get();
    if (c == EOF) throw InputError(path + ": truncated pixel data");
    return (uint8_t)c;
  };
  for (int y = 0; y < h; ++y) {
    uint8_t head[4] = {byte(), byte(), byte(), byte()};
    if (w >= 8 && w < 32768 && head[0] == 2 && head[1] == 2 && ((head[2] << 8) | head[3]) == w) {
      // New-style run-length encoding: each of the 4 components in turn.
      for (int c = 0; c < 4; ++c)
        for (int x = 0; x < w;) {
          int count = byte();
          if (count > 128) {
            count -= 128;
            uint8_t v = byte();
            if (x + count > w) throw InputError(path + ": corrupt run-length data");
            for (int i = 0; i < count; ++i) scan[(size_t)(x++) * 4 + c] = v;
          } else {
            if (count == 0 || x + count > w) throw InputError(path + ": corrupt run-length data");
            for (int i = 0; i < count; ++i) scan[(size_t)(x++) * 4 + c] = byte();
          }
        }
    } else {
      // Flat pixels (old-style RLE is not supported).
      std::memcpy(scan.data(), head, 4);
      for (size_t i = 4; i < scan.size(); ++i) scan[i] = byte();
    }
    for (int x = 0; x < w; ++x) {
      const uint8_t* p = &scan[(size_t)x * 4];
      float f = p[3] ? std::ldexp(1.f, (int)p[3] - (128 + 8)) : 0.f;
      image.pixels[(size_t)y * w + x] =
          RGB((p[0] + 0.5f) * f, (p[1] + 0.5f) * f, (p[2] + 0.5f) * f) * (p[3] ? 1.f : 0.f);
    }
  }
  return image;
}

RGBImage ReadImageHDR(const std::string& path) {
  if (EndsWith(path, ".pfm")) return ReadPFM(path);
  if (EndsWith(path, ".hdr") || EndsWith(path, ".rgbe")) return ReadRGBE(path);
  throw InputError(path + ": unsupported environment image (use a Radiance .hdr or a .pfm)");
}

void WritePFM(const std::string& path, const RGBImage& image) {
  WriteAtomically(path, [&](FILE* f) {
    std::fprintf(f, "PF\n%d %d\n-1.0\n", image.width, image.height);  // negative scale: little endian
    std::vector<float> row((size_t)image.width * 3);
    for (int y = image.height - 1; y >= 0; --y) {
      for (int x = 0; x < image.width; ++x) {
        const RGB& p = image.pixels[(size_t)y * image.width + x];
        row[(size_t)x * 3] = p.r;
        row[(size_t)x * 3 + 1] = p.g;
        row[(size_t)x * 3 + 2] = p.b;
      }
      if (std::fwrite(row.data(), sizeof(float), row.size(), f) != row.size()) return false;
    }
    return true;
  });
}

void WritePNG(const std::string& path, int width, int height, int channels, const std::vector<uint8_t>& pixels) {
  if ((channels != 3 && channels != 4) || pixels.size() != (size_t)width * height * channels)
    throw std::runtime_error(path + ": bad image buffer");
  WriteAtomically(path, [&](FILE* f) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) {
      png_destroy_write_struct(&png, nullptr);
      return false;
    }
    if (setjmp(png_jmpbuf(png))) {
      png_destroy_write_struct(&png, &info);
      return false;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, width, height, 8, channels == 4 ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) png_write_row(png, const_cast<png_bytep>(&pixels[(size_t)y * width * channels]));
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
  });
}

std::vector<uint8_t> ReadPNG(const std::string& path, int* width, int* height, int* channels) {
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str()))
    throw InputError(path + ": cannot read PNG (" + image.message + ")");
  const bool alpha = (image.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  image.format = alpha ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
  // Before the pixels are allocated: at most 16384 pixels a side (the
  // largest image mmrtm-render writes), and no more than deflate (1032:1)
  // and 1-bit samples expanded to 8-bit RGBA (32:1) can make of the file.
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  const double fileBytes = file ? (double)file.tellg() : 0.0;
  if (image.width > 16384 || image.height > 16384 || (double)PNG_IMAGE_SIZE(image) > 1032.0 * 32.0 * fileBytes) {
    png_image_free(&image);
    throw InputError(path + ": " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                     " pixels: more than this PNG reader takes (16384 a side) or the file can hold (corrupt header?)");
  }
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr))
    throw InputError(path + ": cannot read PNG (" + image.message + ")");
  *width = (int)image.width;
  *height = (int)image.height;
  *channels = alpha ? 4 : 3;
  return pixels;
}

}  // namespace mmrtm
