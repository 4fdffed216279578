// Cameras (perspective, orthographic, thin lens) and image files (PFM, RGBE,
// PNG, and environment maps read from them).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "environment_map.h"
#include "host_volume.h"
#include "image_io.h"
#include "mmrtm/camera.h"
#include "TestOutputFolder.h"

namespace mmrtm {
namespace {

std::string Scratch(const char* name) { return (TestOutputFolder() / name).string(); }

CameraView LookAlongY(Projection projection) {
  CameraView c;
  c.projection = projection;
  c.position = {0.f, -10.f, 0.f};
  c.forward = {0.f, 1.f, 0.f};
  c.right = {1.f, 0.f, 0.f};
  c.up = {0.f, 0.f, 1.f};
  c.width = 200;
  c.height = 100;
  c.tanHalfFovY = std::tan(0.25f);
  c.orthoHalfHeight = 3.f;
  return c;
}

TEST(Camera, PerspectiveRaysLeaveThePositionWithinTheFieldOfView) {
  CameraView c = LookAlongY(Projection::Perspective);
  Ray centre = c.GenerateRay(100.f, 50.f, 0.5f, 0.5f);
  EXPECT_NEAR(centre.d.y, 1.f, 1e-6f);
  Ray top = c.GenerateRay(100.f, 0.f, 0.5f, 0.5f);
  EXPECT_NEAR(std::atan2(top.d.z, top.d.y), 0.25f, 1e-5f);  // half the vertical field of view, up
  Ray right = c.GenerateRay(200.f, 50.f, 0.5f, 0.5f);
  EXPECT_NEAR(right.d.x / right.d.y, 2.f * std::tan(0.25f), 1e-5f);  // aspect 2
  EXPECT_NEAR(Length(top.o - c.position), 0.f, 1e-6f);
}

TEST(Camera, OrthographicRaysAreParallel) {
  CameraView c = LookAlongY(Projection::Orthographic);
  Ray a = c.GenerateRay(0.f, 0.f, 0.5f, 0.5f), b = c.GenerateRay(200.f, 100.f, 0.5f, 0.5f);
  EXPECT_NEAR(Dot(a.d, b.d), 1.f, 1e-6f);
  EXPECT_NEAR(a.o.z, 3.f, 1e-5f);
  EXPECT_NEAR(b.o.z, -3.f, 1e-5f);
  EXPECT_NEAR(b.o.x - a.o.x, 12.f, 1e-4f);  // 2 * aspect * half height
}

TEST(Camera, ThinLensFocusesOnItsFocusPlane) {
  CameraView c = LookAlongY(Projection::Perspective);
  c.lensRadius = 0.5f;
  c.focusDistance = 7.f;
  // Rays through one pixel from different lens points meet on the focus plane.
  Ray a = c.GenerateRay(130.f, 40.f, 0.1f, 0.2f), b = c.GenerateRay(130.f, 40.f, 0.9f, 0.7f);
  EXPECT_GT(Length(a.o - b.o), 0.1f);
  auto onFocusPlane = [&](const Ray& r) { return r((c.position.y + 7.f - r.o.y) / r.d.y); };
  EXPECT_NEAR(Length(onFocusPlane(a) - onFocusPlane(b)), 0.f, 1e-4f);
}

// A tile of a 2 x 2 magnified image, as vtkWindowToImageFilter renders it:
// the same film size, half the view window (tan of half the angle halved,
// or half the parallel scale) and the window centre on the tile. Its rays
// must be the large image's rays through the same points. Catches a window
// centre ignored (every tile the middle of the view) or applied with the
// wrong sign or scale (tiles swapped, stretched).
TEST(Camera, ATileWithItsWindowCentreSeesItsPartOfTheLargeImage) {
  for (Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    CameraView large = LookAlongY(projection);
    large.width *= 2;
    large.height *= 2;
    CameraView tile = LookAlongY(projection);
    tile.tanHalfFovY = 0.5f * large.tanHalfFovY;
    tile.orthoHalfHeight = 0.5f * large.orthoHalfHeight;
    tile.windowCenterX = 1.f;   // the right half
    tile.windowCenterY = -1.f;  // the bottom half
    for (float px : {0.f, 37.5f, 200.f})
      for (float py : {0.f, 61.f, 100.f}) {
        const Ray a = tile.GenerateRay(px, py, 0.5f, 0.5f);
        const Ray b = large.GenerateRay(px + tile.width, py + tile.height, 0.5f, 0.5f);
        EXPECT_NEAR(Length(a.d - b.d), 0.f, 1e-5f) << px << " " << py;
        EXPECT_NEAR(Length(a.o - b.o), 0.f, 1e-4f) << px << " " << py;
      }
  }
}

TEST(ImageFiles, PfmRoundTripKeepsFloatsAndOrientation) {
  RGBImage image{3, 2, {RGB(0.f, 1.f, 2.f), RGB(3.f), RGB(4.f), RGB(5.f), RGB(6.f), RGB(1e-8f, 1e8f, 0.5f)}};
  WritePFM(Scratch("roundtrip.pfm"), image);
  RGBImage back = ReadPFM(Scratch("roundtrip.pfm"));
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(back.pixels[i][c], image.pixels[i][c]) << i;
}

TEST(ImageFiles, PngRoundTrip) {
  std::vector<uint8_t> rgba = {255, 0, 0, 255, 0, 128, 0, 64, 1, 2, 3, 0, 9, 8, 7, 6};
  WritePNG(Scratch("roundtrip.png"), 2, 2, 4, rgba);
  int w, h, channels;
  std::vector<uint8_t> back = ReadPNG(Scratch("roundtrip.png"), &w, &h, &channels);
  EXPECT_EQ(w, 2);
  EXPECT_EQ(h, 2);
  EXPECT_EQ(channels, 4);
  EXPECT_EQ(back, rgba);
}

// Radiance .hdr: one scanline run-length encoded, one flat (width < 8 is flat).
TEST(ImageFiles, RadianceHdrDecodes) {
  const std::string path = Scratch("tiny.hdr");
  {
    std::ofstream f(path, std::ios::binary);
    f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n";
    // Row 0, RLE: each component as one run of 8 equal bytes: R=128 G=64 B=0 E=129 -> (1.0, 0.5, 0.0)-ish.
    const unsigned char header[4] = {2, 2, 0, 8};
    f.write(reinterpret_cast<const char*>(header), 4);
    for (unsigned char v : {128, 64, 0, 129}) {
      const unsigned char run[2] = {128 + 8, v};
      f.write(reinterpret_cast<const char*>(run), 2);
    }
    // Row 1, flat pixels: 8 x (R=32 G=32 B=32 E=128).
    for (int i = 0; i < 8; ++i) {
      const unsigned char px[4] = {32, 32, 32, 128};
      f.write(reinterpret_cast<const char*>(px), 4);
    }
  }
  RGBImage image = ReadRGBE(path);
  ASSERT_EQ(image.width, 8);
  ASSERT_EQ(image.height, 2);
  EXPECT_NEAR(image.pixels[3].r, (128 + 0.5f) / 128.f, 1e-6f);  // mantissa * 2^(129-136)
  EXPECT_NEAR(image.pixels[3].g, (64 + 0.5f) / 128.f, 1e-6f);
  EXPECT_NEAR(image.pixels[8 + 5].b, (32 + 0.5f) / 256.f, 1e-6f);

  std::shared_ptr<EnvironmentMap> env = EnvironmentMap::Load(path, 2.f);
  EXPECT_NEAR(env->Texels()[3].r, 2.f * (128 + 0.5f) / 128.f, 1e-5f);
}

TEST(ImageFiles, BadFilesGiveErrorsNamingThem) {
  const std::string text = Scratch("not-an-image.hdr");
  std::ofstream(text) << "hello";
  try {
    ReadRGBE(text);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not-an-image.hdr"), std::string::npos);
  }
  RGBImage image{4, 4, std::vector<RGB>(16, RGB(1.f))};
  WritePFM(Scratch("cut.pfm"), image);
  std::filesystem::resize_file(Scratch("cut.pfm"), 60);
  EXPECT_THROW(ReadPFM(Scratch("cut.pfm")), InputError);
  EXPECT_THROW(EnvironmentMap::Load(Scratch("image.exr")), InputError);
  EXPECT_THROW(WritePFM(Scratch("no-such-folder/out.pfm"), image), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(Scratch("no-such-folder/out.pfm.partial")));
}

}  // namespace
}  // namespace mmrtm
