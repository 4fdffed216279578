// VTK's cropping regions in the tracer (Classifier::cropKeep): space cut by
// two planes per axis into 27 regions, numbered as VTK numbers them (x
// fastest), each kept or emptied by its bit. Checks VTK's named flag sets
// region by region (a wrong numbering, an axis swapped or a plane taken as
// the other side fails), that a crop edit does not refit the majorants and
// that the minorants are dropped while cropping (a cropped cell's density
// falls below its minorant), and that the default crops nothing.
#include <gtest/gtest.h>

#include "TestSceneHelpers.h"

namespace mmrtm {
namespace {

// VTK's flag sets (vtkVolumeMapper.h).
constexpr uint32_t kSubvolume = 0x0002000, kFence = 0x2ebfeba, kInvertedFence = 0x5140145, kCross = 0x0417410,
                   kInvertedCross = 0x7be8bef;

Scene Cube() {
  // 30 voxels a side, unit spacing at the origin, density 1 everywhere.
  return test::MakeMediumScene(test::MakeConstantVolume(30, 1.f), 1.f, {0.8f, 0.8f, 0.8f});
}

void CropAt(Scene& s, uint32_t flags) {
  s.cropping.keep = flags;
  for (int a = 0; a < 3; ++a) {
    s.cropping.lo[a] = 10.f;
    s.cropping.hi[a] = 20.f;
  }
}

TEST(Cropping, EachRegionIsKeptExactlyWhenItsBitIsSet) {
  for (uint32_t flags : {kSubvolume, kFence, kInvertedFence, kCross, kInvertedCross}) {
    Scene s = Cube();
    CropAt(s, flags);
    const SceneView view = s.Build();
    for (int region = 0; region < 27; ++region) {
      const int r[3] = {region % 3, (region / 3) % 3, region / 9};
      Vec3 p;
      float* x = &p.x;
      for (int a = 0; a < 3; ++a) x[a] = r[a] == 0 ? 5.f : r[a] == 1 ? 15.f : 25.f;
      const bool kept = (flags >> region) & 1u;
      EXPECT_EQ(view.classifier.Classify(p).sigma_t > 0.f, kept)
          << "flags 0x" << std::hex << flags << std::dec << ", region " << region;
    }
  }
}

TEST(Cropping, TheDefaultCropsNothing) {
  Scene s = Cube();
  const SceneView view = s.Build();
  EXPECT_EQ(view.classifier.cropKeep, Classifier::kNoCropping);
  EXPECT_GT(view.classifier.Classify({2.f, 2.f, 2.f}).sigma_t, 0.f);
  EXPECT_GT(view.classifier.Classify({27.f, 15.f, 3.f}).sigma_t, 0.f);
  EXPECT_NE(view.majorants.grid.minorants, nullptr);
}

TEST(Cropping, ACropEditKeepsTheMajorantsAndDropsTheMinorants) {
  Scene s = Cube();
  s.Build();
  CropAt(s, kFence);
  const SceneView cropped = s.Build();
  EXPECT_FALSE(s.GridRefittedByLastBuild()) << "the majorants bound the uncropped volume";
  EXPECT_EQ(cropped.majorants.grid.minorants, nullptr);
  EXPECT_NE(cropped.majorants.grid.majorants, nullptr);
}

// The planes are in the data's coordinates: a world-to-data transform (the
// volume's matrix, inverted) moves the regions with the volume.
TEST(Cropping, ThePlanesMoveWithTheVolume) {
  Scene s = Cube();
  CropAt(s, kSubvolume);
  s.cropping.worldToData.m[0][3] = -100.f;  // data x = world x - 100
  const SceneView view = s.Build();
  EXPECT_EQ(view.classifier.Classify({15.f, 15.f, 15.f}).sigma_t, 0.f) << "data x -85: below the low plane";
}

}  // namespace
}  // namespace mmrtm
