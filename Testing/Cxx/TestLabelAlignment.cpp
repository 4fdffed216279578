// Tests of AlignLabelsToVolume on synthetic label maps (mirrored, coarser,
// partly outside, far away) and of its use by SceneFromJson.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "label_alignment.h"
#include "scene_json.h"
#include "TestTypedVolumes.h"

using namespace mmrtm;
using namespace mmrtm::test;

namespace {

// A label per voxel that differs between neighbours in every direction.
double LabelOf(int i, int j, int k) { return 1 + i + 7 * j + 31 * k; }

HostVolume Reference() {
  return MakeTyped<float>(
      {6, 5, 4}, [](int i, int, int) { return i; }, Grid({10, 20, 30}, {1, 2, 3}), "scalars");
}

HostVolume Labels(std::array<int, 3> dims, const std::function<double(int, int, int)>& f, const Affine3& grid) {
  return MakeTyped<uint16_t>(dims, f, grid, "labels", Interpolation::Nearest);
}

void ExpectVoxels(const HostVolume& v, const std::function<double(int, int, int)>& expected) {
  for (int k = 0; k < v.dims[2]; ++k)
    for (int j = 0; j < v.dims[1]; ++j)
      for (int i = 0; i < v.dims[0]; ++i)
        ASSERT_EQ(At(v, i, j, k), (float)expected(i, j, k)) << "voxel " << i << ", " << j << ", " << k;
}

std::string ErrorOf(const HostVolume& labels, const HostVolume& reference) {
  try {
    AlignLabelsToVolume(labels, reference);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(LabelAlignment, SameGridComesBackUnchanged) {
  const HostVolume ref = Reference();
  HostVolume labels = Labels(ref.dims, LabelOf, ref.indexToWorld);
  labels.indexToWorld.m[0][3] += 1e-4f;  // well within 1e-3 voxel
  bool resampled = true;
  HostVolume out = AlignLabelsToVolume(labels, ref, &resampled);
  EXPECT_FALSE(resampled);
  EXPECT_EQ(out.voxels, labels.voxels);
  EXPECT_EQ(out.indexToWorld.m[0][3], labels.indexToWorld.m[0][3]);
  EXPECT_EQ(out.type, VoxelType::UInt16);
}

TEST(LabelAlignment, MirroredGridAlignsExactly) {
  // The same labels stored with the x and y axes reversed (as a file written
  // in RAS rather than LPS order would be): negative directions, flipped voxels.
  const HostVolume ref = Reference();
  const auto [nx, ny, nz] = ref.dims;
  const Vec3 far = ref.indexToWorld.ApplyPoint({float(nx - 1), float(ny - 1), 0.f});
  HostVolume labels = Labels(
      ref.dims, [&](int i, int j, int k) { return LabelOf(nx - 1 - i, ny - 1 - j, k); },
      Grid({far.x, far.y, far.z}, {1, 2, 3}, {-1, 0, 0, 0, -1, 0, 0, 0, 1}));
  bool resampled = false;
  HostVolume out = AlignLabelsToVolume(labels, ref, &resampled);
  EXPECT_TRUE(resampled);
  EXPECT_EQ(out.dims, ref.dims);
  EXPECT_EQ(out.type, VoxelType::UInt16);
  EXPECT_EQ(out.interpolation, Interpolation::Nearest);
  EXPECT_EQ(out.name, "labels");
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(out.indexToWorld.m[r][c], ref.indexToWorld.m[r][c]);
  ExpectVoxels(out, LabelOf);
  (void)nz;
}

TEST(LabelAlignment, RotatedGridAlignsExactly) {
  // Reference axes turned 90 degrees about z (a direction matrix whose
  // columns are permuted axes): reference (i, j, k) lies at world (-j, i, 2k).
  const HostVolume ref = MakeTyped<int16_t>(
      {4, 6, 3}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 2}, {0, -1, 0, 1, 0, 0, 0, 0, 1}));
  // Axis-aligned labels over the same box: label (x, y, k) lies at world
  // (x - 5, y, 2k), which is reference (y, 5 - x, k).
  HostVolume labels = Labels(
      {6, 4, 3}, [](int x, int y, int k) { return LabelOf(y, 5 - x, k); }, Grid({-5, 0, 0}, {1, 1, 2}));
  bool resampled = false;
  HostVolume out = AlignLabelsToVolume(labels, ref, &resampled);
  EXPECT_TRUE(resampled);
  ExpectVoxels(out, LabelOf);
}

TEST(LabelAlignment, HalfResolutionUpsamples) {
  const HostVolume ref = MakeTyped<float>(
      {8, 8, 8}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 1}));
  // Each label voxel covers 2x2x2 reference voxels: its centre is at the
  // middle of their block, so no reference centre lies on a boundary.
  HostVolume labels =
      MakeTyped<uint8_t>({4, 4, 4}, LabelOf, Grid({0.5, 0.5, 0.5}, {2, 2, 2}), "labels", Interpolation::Nearest);
  bool resampled = false;
  HostVolume out = AlignLabelsToVolume(labels, ref, &resampled);
  EXPECT_TRUE(resampled);
  EXPECT_EQ(out.type, VoxelType::UInt8);
  EXPECT_EQ(out.dims, ref.dims);
  ExpectVoxels(out, [](int i, int j, int k) { return LabelOf(i / 2, j / 2, k / 2); });
}

TEST(LabelAlignment, VoxelsOutsideTheLabelMapAreBackground) {
  const HostVolume ref = MakeTyped<float>(
      {8, 6, 4}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 1}));
  // Covers reference x 3..7 only (and y 0..5, z 0..3), shifted by a fraction of a voxel.
  HostVolume labels = Labels({6, 6, 4}, LabelOf, Grid({3.2, 0, 0}, {1, 1, 1}));
  HostVolume out = AlignLabelsToVolume(labels, ref);
  ExpectVoxels(out, [](int i, int j, int k) { return i < 3 ? 0.0 : LabelOf(i - 3, j, k); });
}

TEST(LabelAlignment, FarAwayLabelMapThrows) {
  const HostVolume ref = Reference();
  HostVolume labels = Labels(ref.dims, LabelOf, Grid({1000, 20, 30}, {1, 2, 3}));
  const std::string message = ErrorOf(labels, ref);
  EXPECT_NE(message.find("labels.nrrd"), std::string::npos) << message;
  EXPECT_NE(message.find("does not overlap"), std::string::npos) << message;
  EXPECT_NE(message.find("scalars.nrrd"), std::string::npos) << message;
}

TEST(LabelAlignment, NoSurvivingLabelThrows) {
  const HostVolume ref = MakeTyped<float>(
      {8, 8, 8}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 1}));
  // Overlaps in x 4..7, but its labels are all beyond x = 8.
  HostVolume labels = Labels(
      {10, 8, 8}, [](int i, int, int) { return i >= 5 ? 3 : 0; }, Grid({4, 0, 0}, {1, 1, 1}));
  const std::string message = ErrorOf(labels, ref);
  EXPECT_NE(message.find("labels.nrrd: no label is left"), std::string::npos) << message;
  EXPECT_NE(message.find("scalars.nrrd"), std::string::npos) << message;
}

// SceneFromJson puts a read label map on the grid of `scalars` and says so.
TEST(LabelAlignment, SceneResamplesReadLabelMaps) {
  const nlohmann::json doc = nlohmann::json::parse(R"({
    "materials": {"m": {"tfs": {"density": [{"type": "cdptf", "proxy": "labels", "points": [[1, 1]]}]}}}
  })");
  SceneInputs in;
  in.volumes["scalars"] = MakeTyped<float>(
      {8, 8, 8}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 1}), "scalars");
  in.volumes["labels"] =
      MakeTyped<uint8_t>({4, 4, 4}, LabelOf, Grid({0.5, 0.5, 0.5}, {2, 2, 2}), "labels", Interpolation::Nearest);
  testing::internal::CaptureStderr();
  Scene scene = SceneFromJson(doc, in);
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("labels.nrrd"), std::string::npos) << warning;
  EXPECT_NE(warning.find("resampled"), std::string::npos) << warning;
  EXPECT_NE(warning.find("scalars.nrrd"), std::string::npos) << warning;
  EXPECT_EQ(std::count(warning.begin(), warning.end(), '\n'), 1);
  const int l = scene.ProxyIndex("labels");
  ASSERT_GE(l, 0);
  EXPECT_EQ(scene.proxies[l].dims, (std::array<int, 3>{8, 8, 8}));
  ExpectVoxels(scene.proxies[l], [](int i, int j, int k) { return LabelOf(i / 2, j / 2, k / 2); });

  // A label map on the grid already: no copy, no warning. A continuous proxy
  // on another grid is left as it is.
  in.volumes["labels"] =
      MakeTyped<uint8_t>({8, 8, 8}, LabelOf, Grid({0, 0, 0}, {1, 1, 1}), "labels", Interpolation::Nearest);
  testing::internal::CaptureStderr();
  scene = SceneFromJson(doc, in);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(scene.proxies[scene.ProxyIndex("labels")].voxels, in.volumes["labels"].voxels);
  in.volumes["labels"] = MakeTyped<uint8_t>({4, 4, 4}, LabelOf, Grid({0.5, 0.5, 0.5}, {2, 2, 2}), "labels");
  testing::internal::CaptureStderr();
  scene = SceneFromJson(doc, in);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(scene.proxies[scene.ProxyIndex("labels")].dims, (std::array<int, 3>{4, 4, 4}));
}

TEST(LabelAlignment, SceneLeavesUnreadLabelMapsAlone) {
  // An unread label map is dropped before alignment: even one far away is no error.
  const nlohmann::json doc = nlohmann::json::parse(R"({"materials": {"m": {}}})");
  SceneInputs in;
  in.volumes["scalars"] = MakeTyped<float>(
      {8, 8, 8}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 1}), "scalars");
  in.volumes["labels"] =
      MakeTyped<uint8_t>({4, 4, 4}, LabelOf, Grid({500, 0, 0}, {2, 2, 2}), "labels", Interpolation::Nearest);
  testing::internal::CaptureStderr();
  Scene scene = SceneFromJson(doc, in);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(scene.ProxyIndex("labels"), -1);
}

TEST(LabelAlignment, SceneErrorNamesBothFiles) {
  const nlohmann::json doc = nlohmann::json::parse(R"({
    "materials": {"m": {"tfs": {"density": [{"type": "cdptf", "proxy": "labels", "points": [[1, 1]]}]}}}
  })");
  SceneInputs in;
  in.volumes["scalars"] = MakeTyped<float>(
      {8, 8, 8}, [](int, int, int) { return 0; }, Grid({0, 0, 0}, {1, 1, 1}), "scalars");
  in.volumes["labels"] =
      MakeTyped<uint8_t>({4, 4, 4}, LabelOf, Grid({500, 0, 0}, {2, 2, 2}), "labels", Interpolation::Nearest);
  try {
    SceneFromJson(doc, in);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("labels.nrrd"), std::string::npos) << message;
    EXPECT_NE(message.find("scalars.nrrd"), std::string::npos) << message;
  }
}
