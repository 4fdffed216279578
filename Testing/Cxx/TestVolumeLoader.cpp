// Tests of mmrtm::LoadVolume (DICOM series: TestDicomLoader.cpp) on the real volumes in MMRTM_SHARED_DATA_DIR and
// on small broken or hand-made files written to the test's own output folder.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "label_alignment.h"
#include "mmrtmVolumeLoader.h"
#include "TestOutputFolder.h"

namespace fs = std::filesystem;
using mmrtm::HostVolume;
using mmrtm::InputError;
using mmrtm::LoadVolume;
using mmrtm::Vec3;
using mmrtm::VoxelType;

namespace {

std::string Data(const std::string& name) { return std::string(MMRTM_SHARED_DATA_DIR) + "/" + name; }

// A fresh path in the test's own output folder (any old file there is removed).
std::string Scratch(const std::string& name) {
  const fs::path dir = TestOutputFolder();
  fs::remove_all(dir / name);
  return (dir / name).string();
}

Vec3 World(const HostVolume& v, float i, float j, float k) { return v.indexToWorld.ApplyPoint({i, j, k}); }

void ExpectWorld(const HostVolume& v, Vec3 index, Vec3 expected, float tolerance = 1e-3f) {
  const Vec3 w = World(v, index.x, index.y, index.z);
  SCOPED_TRACE(v.source + " index (" + std::to_string(index.x) + ", " + std::to_string(index.y) + ", " +
               std::to_string(index.z) + ")");
  EXPECT_NEAR(w.x, expected.x, tolerance);
  EXPECT_NEAR(w.y, expected.y, tolerance);
  EXPECT_NEAR(w.z, expected.z, tolerance);
}

float ValueAt(const HostVolume& v, int i, int j, int k) {
  return v.Value(i + (int64_t)v.dims[0] * (j + (int64_t)v.dims[1] * k));
}

// Expects LoadVolume(path) to throw InputError naming the file and containing `text`.
void ExpectInputError(const std::string& path, const std::string& text = "") {
  SCOPED_TRACE(path);
  try {
    LoadVolume(path);
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(fs::path(path).filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(text), std::string::npos) << "expected '" << text << "' in: " << msg;
  }
}

void CopyTruncated(const std::string& from, const std::string& to, double fraction) {
  std::ifstream in(from, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 0u) << from;
  std::ofstream(to, std::ios::binary).write(bytes.data(), (std::streamsize)(bytes.size() * fraction));
}

// A raw little-endian float NRRD with the given header fields.
void WriteFloatNrrd(const std::string& path, const std::string& fields, const std::vector<float>& values) {
  std::ofstream out(path, std::ios::binary);
  out << "NRRD0004\ntype: float\nencoding: raw\nendian: little\n" << fields << "\n";
  out.write(reinterpret_cast<const char*>(values.data()), (std::streamsize)(values.size() * sizeof(float)));
}

// The voxel bytes of a .nii.gz as stored (vox_offset from the header).
std::vector<uint8_t> ReadNiftiVoxelBytes(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  EXPECT_NE(f, nullptr);
  std::vector<uint8_t> all;
  uint8_t buffer[1 << 16];
  int n;
  while ((n = gzread(f, buffer, sizeof buffer)) > 0) all.insert(all.end(), buffer, buffer + n);
  gzclose(f);
  float voxOffset = 0;
  std::memcpy(&voxOffset, all.data() + 108, 4);
  return std::vector<uint8_t>(all.begin() + (size_t)voxOffset, all.end());
}

// The stored pixels of an uncompressed 16-bit DICOM file: the last (7FE0,0010)
// element, implicit or explicit VR.
std::vector<uint16_t> ReadDicomPixels(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = bytes.rfind(std::string("\xE0\x7F\x10\x00", 4));
  EXPECT_NE(at, std::string::npos);
  size_t data = at + 8;
  uint32_t length;
  if (bytes.compare(at + 4, 2, "OW") == 0 || bytes.compare(at + 4, 2, "OB") == 0) {
    std::memcpy(&length, &bytes[at + 8], 4);
    data = at + 12;
  } else {
    std::memcpy(&length, &bytes[at + 4], 4);
  }
  std::vector<uint16_t> pixels(length / 2);
  std::memcpy(pixels.data(), &bytes[data], pixels.size() * 2);
  return pixels;
}

// ---------------------------------------------------------------------------
// Real volumes
// ---------------------------------------------------------------------------

TEST(VolumeLoader, NrrdCraniumHeadCt) {
  const HostVolume v = LoadVolume(Data("ct_head_cranium.nrrd"), "ct");
  EXPECT_EQ(v.name, "ct");
  EXPECT_EQ(v.dims, (std::array<int, 3>{256, 256, 108}));
  EXPECT_EQ(v.type, VoxelType::Int16);
  ExpectWorld(v, {0, 0, 0}, {0, 0, 0});
  ExpectWorld(v, {1, 0, 0}, {0.9570312f, 0, 0}, 1e-6f);
  ExpectWorld(v, {0, 1, 0}, {0, 0.9570312f, 0}, 1e-6f);
  ExpectWorld(v, {0, 0, 1}, {0, 0, 1.5f}, 1e-6f);
  const auto range = v.ValueRange();
  EXPECT_EQ(range[0], -1024.f);
  EXPECT_EQ(range[1], 2986.f);
  // int16 as stored: the reader's array is the volume's buffer (no second copy).
  EXPECT_TRUE(v.voxels.IsBorrowed());
}

TEST(VolumeLoader, NrrdHeadsqSpacingsField) {
  const HostVolume v = LoadVolume(Data("ct_head_headsq.nrrd"));
  EXPECT_EQ(v.dims, (std::array<int, 3>{64, 64, 93}));
  EXPECT_EQ(v.type, VoxelType::Int16);
  ExpectWorld(v, {1, 1, 1}, {3.2f, 3.2f, 1.5f});
  EXPECT_EQ(v.ValueRange()[1], 3926.f);
}

TEST(VolumeLoader, Inv3MatchesRepackedNrrd) {
  if (!fs::exists(mmrtm::DefaultVolumePath()))
    GTEST_SKIP() << mmrtm::DefaultVolumePath() << " is absent (Debian package invesalius-examples)";
  const HostVolume inv3 = LoadVolume(mmrtm::DefaultVolumePath());
  const HostVolume nrrd = LoadVolume(Data("ct_head_cranium.nrrd"));
  EXPECT_EQ(inv3.dims, nrrd.dims);
  EXPECT_EQ(inv3.type, nrrd.type);
  EXPECT_TRUE(inv3.voxels == nrrd.voxels) << "voxel bytes differ";
  // Same x and z axes; the .inv3 rows run posterior to anterior, so its y
  // axis is flipped (see LoadInVesalius) and the whole box is the same.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(inv3.indexToWorld.m[r][c], (r == 1 && c == 1 ? -1.f : 1.f) * nrrd.indexToWorld.m[r][c], 1e-6f);
  const auto a = inv3.WorldBounds(), b = nrrd.WorldBounds();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a[0][i], b[0][i], 1e-3f);
    EXPECT_NEAR(a[1][i], b[1][i], 1e-3f);
  }
}

TEST(VolumeLoader, NiftiBonsaiUInt8) {
  const HostVolume v = LoadVolume(Data("bonsai.nii.gz"));
  EXPECT_EQ(v.dims, (std::array<int, 3>{256, 256, 256}));
  EXPECT_EQ(v.type, VoxelType::UInt8);
  EXPECT_TRUE(v.voxels.IsBorrowed());  // the reader's array, taken over
  EXPECT_EQ(ValueAt(v, 128, 128, 128), 69.f);
  // qform/sform: RAS (-127, -127, -128) at index 0, identity axes.
  ExpectWorld(v, {0, 0, 0}, {127, 127, -128});
  ExpectWorld(v, {1, 1, 1}, {126, 126, -127});
}

TEST(VolumeLoader, NiftiMrHeadSlopeGivesFloat) {
  const HostVolume v = LoadVolume(Data("mr_head.nii.gz"));
  EXPECT_EQ(v.dims, (std::array<int, 3>{160, 232, 160}));
  // uint8 * scl_slope 2.007843 is not integer-valued: float32.
  EXPECT_EQ(v.type, VoxelType::Float32);
  EXPECT_FALSE(v.voxels.IsBorrowed());  // rescaled: a buffer of its own
  EXPECT_NEAR(ValueAt(v, 80, 116, 80), 51 * 2.007843255996704, 1e-3);
  EXPECT_NEAR(v.ValueRange()[1], 255 * 2.007843255996704, 1e-3);
  // sform rows (1,0,0,-388.26) (0,0.898437,0,-81.12) (0,0,0.898437,405.421) in RAS.
  ExpectWorld(v, {0, 0, 0}, {388.26f, 81.11996f, 405.42099f});
  ExpectWorld(v, {159, 231, 159}, {229.26f, -126.41899f, 405.42099f + 159 * 0.898437f}, 2e-3f);
}

// mr_head_brain_mask.nrrd (LPS space directions) is the same head with its
// array mirrored in x and y: both formats must put a voxel at one place.
TEST(VolumeLoader, NiftiAndNrrdOfOneHeadAgreeInWorld) {
  const HostVolume nifti = LoadVolume(Data("mr_head.nii.gz"));
  const HostVolume mask = LoadVolume(Data("mr_head_brain_mask.nrrd"));
  ASSERT_EQ(mask.dims, nifti.dims);
  ExpectWorld(mask, {0, 0, 0}, {229.26f, -126.419f, 405.421f});
  for (Vec3 i : {Vec3{0, 0, 0}, Vec3{10, 20, 30}, Vec3{159, 231, 159}}) {
    const Vec3 w = World(nifti, 159 - i.x, 231 - i.y, i.z);
    ExpectWorld(mask, i, w, 2e-3f);
  }
}

// A label map with another orientation (the NRRD brain mask, its array
// mirrored in x and y against the MRI) aligned onto the MRI's grid in world
// space gives the labels of mr_head_labels.nii.gz, which was made on that
// grid by flipping the arrays: brain (1) exactly where the mask is set.
TEST(VolumeLoader, MirroredLabelMapAlignsToTheVolume) {
  const HostVolume mri = LoadVolume(Data("mr_head.nii.gz"));
  const HostVolume mask = LoadVolume(Data("mr_head_brain_mask.nrrd"), "labels", mmrtm::Interpolation::Nearest);
  const HostVolume labels = LoadVolume(Data("mr_head_labels.nii.gz"), "labels", mmrtm::Interpolation::Nearest);
  bool resampled = false;
  const HostVolume aligned = mmrtm::AlignLabelsToVolume(mask, mri, &resampled);
  EXPECT_TRUE(resampled);
  ASSERT_EQ(aligned.dims, mri.dims);
  int64_t brain = 0, disagree = 0, naiveDisagree = 0;
  for (int64_t i = 0; i < aligned.VoxelCount(); ++i) {
    const bool isBrain = labels.Value(i) == 1.f;
    brain += isBrain;
    disagree += isBrain != (aligned.Value(i) != 0.f);
    naiveDisagree += isBrain != (mask.Value(i) != 0.f);
  }
  EXPECT_GT(brain, 100000);
  EXPECT_EQ(disagree, 0) << "voxels where the aligned mask and the brain label differ";
  // The test is not vacuous: the brain is nearly symmetric, yet the mirrored
  // array taken voxel by voxel is wrong in many voxels.
  EXPECT_GT(naiveDisagree, brain / 10);
}

TEST(VolumeLoader, NiftiInt32BecomesInt16) {
  const HostVolume v = LoadVolume(Data("ct_abdomen.nii.gz"));
  EXPECT_EQ(v.dims, (std::array<int, 3>{122, 101, 112}));
  EXPECT_EQ(v.type, VoxelType::Int16);
  EXPECT_EQ(ValueAt(v, 61, 50, 56), 164.f);
  const auto range = v.ValueRange();
  EXPECT_EQ(range[0], -1207.f);
  EXPECT_EQ(range[1], 3382.f);
  // sform only (qform_code 0): diag(3,3,3), offset RAS (-177.956, 11.319, 94.302).
  ExpectWorld(v, {0, 0, 0}, {177.95633f, -11.319f, 94.30176f});
  ExpectWorld(v, {1, 1, 1}, {174.95633f, -14.319f, 97.30176f});
}

// A left-handed sform (qfac -1): vtkNIFTIImageReader reverses the slices;
// the world matrix and the voxels must still agree with the file.
TEST(VolumeLoader, NiftiLeftHandedSformKeepsVoxelsInPlace) {
  const std::string path = Data("ct_abdomen_dicom_j2k_labels.nii.gz");
  const HostVolume v = LoadVolume(path);
  ASSERT_EQ(v.dims, (std::array<int, 3>{512, 512, 20}));
  ASSERT_EQ(v.type, VoxelType::UInt8);
  // File voxel (i, j, k) is at RAS (249.512 - 0.977 i, -61.512 + 0.977 j, -804.5 + 2 k).
  const std::vector<uint8_t> file = ReadNiftiVoxelBytes(path);
  ASSERT_EQ(file.size(), v.voxels.size());
  const mmrtm::Affine3 worldToIndex = mmrtm::AffineInverse(v.indexToWorld);
  int64_t labelled = 0;
  bool sameWorld = true;
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 512; ++j)
      for (int i = 0; i < 512; ++i) {
        const uint8_t fileValue = file[i + 512 * (j + 512 * (size_t)k)];
        if (fileValue == 0) continue;
        ++labelled;
        // Find the stored voxel at this file voxel's world position.
        const Vec3 lps{-(249.51171875f - 0.9765625f * i), -(-61.51171875f + 0.9765625f * j), -804.5f + 2.f * k};
        const Vec3 idx = worldToIndex.ApplyPoint(lps);
        const int si = (int)std::lround(idx.x), sj = (int)std::lround(idx.y), sk = (int)std::lround(idx.z);
        if (si < 0 || sj < 0 || sk < 0 || si >= 512 || sj >= 512 || sk >= 20 || ValueAt(v, si, sj, sk) != fileValue)
          sameWorld = false;
      }
  EXPECT_GT(labelled, 1000);
  EXPECT_TRUE(sameWorld);
}

TEST(VolumeLoader, VtiHydrogenFloat) {
  const HostVolume v = LoadVolume(Data("hydrogen.vti"));
  EXPECT_EQ(v.dims, (std::array<int, 3>{64, 64, 64}));
  EXPECT_EQ(v.type, VoxelType::Float32);
  ExpectWorld(v, {0, 0, 0}, {0, 0, 0});
  ExpectWorld(v, {63, 63, 63}, {63, 63, 63});
  EXPECT_NEAR(v.ValueRange()[1], 1.f, 1e-6f);
}

TEST(VolumeLoader, LegacyVtkStructuredPoints) {
  const HostVolume iron = LoadVolume(Data("iron_protein.vtk"));
  EXPECT_EQ(iron.dims, (std::array<int, 3>{68, 68, 68}));
  EXPECT_EQ(iron.type, VoxelType::UInt8);
  ExpectWorld(iron, {1, 2, 3}, {1, 2, 3});
  // Scalars plus vectors: the scalars are taken; ORIGIN 100 80 1.
  const HostVolume carotid = LoadVolume(Data("carotid_flow.vtk"));
  EXPECT_EQ(carotid.dims, (std::array<int, 3>{76, 49, 45}));
  EXPECT_EQ(carotid.type, VoxelType::Float32);
  ExpectWorld(carotid, {0, 0, 0}, {100, 80, 1});
}

TEST(VolumeLoader, MetaImageFrogLabels) {
  const HostVolume v = LoadVolume(Data("frogtissue.mhd"), "labels", mmrtm::Interpolation::Nearest);
  EXPECT_EQ(v.dims, (std::array<int, 3>{500, 470, 136}));
  EXPECT_EQ(v.type, VoxelType::UInt8);
  EXPECT_EQ(v.interpolation, mmrtm::Interpolation::Nearest);
  ExpectWorld(v, {1, 1, 1}, {1, 1, 1.5f});
  const auto range = v.ValueRange();
  EXPECT_EQ(range[0], 0.f);
  EXPECT_LE(range[1], 29.f);
  EXPECT_GT(range[1], 0.f);
}

TEST(VolumeLoader, DicomChestSeries) {
  const std::string folder = Data("ct_chest_dicom");
  const HostVolume v = LoadVolume(folder);
  EXPECT_EQ(v.dims, (std::array<int, 3>{512, 512, 92}));
  EXPECT_EQ(v.type, VoxelType::Int16);  // uint16 stored, rescale intercept -1000
  // Slices ascend along the normal (0,0,1): index 0 is the most inferior
  // slice, 000197.dcm, ImagePositionPatient (-201, -59, -679.800049); the
  // most superior, 000126.dcm, is at z -406.800049. Rows go down as in the file.
  ExpectWorld(v, {0, 0, 0}, {-201, -59, -679.800049f});
  ExpectWorld(v, {1, 1, 0}, {-201 + 0.78125f, -59 + 0.78125f, -679.800049f});
  ExpectWorld(v, {0, 0, 91}, {-201, -59, -406.800049f});
  ExpectWorld(v, {511, 511, 91}, {-201 + 511 * 0.78125f, -59 + 511 * 0.78125f, -406.800049f});
  const std::vector<uint16_t> inferior = ReadDicomPixels(folder + "/000197.dcm");
  const std::vector<uint16_t> superior = ReadDicomPixels(folder + "/000126.dcm");
  ASSERT_EQ(inferior.size(), 512u * 512u);
  ASSERT_EQ(superior.size(), 512u * 512u);
  for (auto [col, row] : {std::pair{200, 100}, std::pair{256, 400}, std::pair{300, 256}, std::pair{0, 0}}) {
    EXPECT_EQ(ValueAt(v, col, row, 0), (float)inferior[row * 512 + col] - 1000.f) << col << ", " << row;
    EXPECT_EQ(ValueAt(v, col, row, 91), (float)superior[row * 512 + col] - 1000.f) << col << ", " << row;
  }
}

TEST(VolumeLoader, FourComponentsAreRejected) {
  ExpectInputError(Data("vase_4comp.vti"), "has 4 components; a single-component volume is needed");
}

// ---------------------------------------------------------------------------
// Hand-made NRRDs: geometry conversion and vtkNrrdReader's quirks
// ---------------------------------------------------------------------------

// RAS space directions become LPS; a 4-sample x axis stays an axis.
TEST(VolumeLoader, NrrdRasSpaceBecomesLps) {
  const std::string path = Scratch("ras.nrrd");
  std::vector<float> values(4 * 3 * 2);
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.5f * (float)i;
  WriteFloatNrrd(path,
                 "dimension: 3\nsizes: 4 3 2\nspace: right-anterior-superior\n"
                 "space directions: (2,0,0) (0,3,0) (0,0,4)\nspace origin: (10,20,30)\n",
                 values);
  const HostVolume v = LoadVolume(path);
  EXPECT_EQ(v.dims, (std::array<int, 3>{4, 3, 2}));
  EXPECT_EQ(v.type, VoxelType::Float32);
  EXPECT_EQ(ValueAt(v, 3, 2, 1), 0.5f * 23);
  ExpectWorld(v, {0, 0, 0}, {-10, -20, 30});
  ExpectWorld(v, {1, 1, 1}, {-12, -23, 34});
}

// vtkNrrdReader reverses the rows of raw files in LAS space: every voxel must
// still sit where the header puts its file position.
TEST(VolumeLoader, NrrdLasSpaceKeepsVoxelsInPlace) {
  const std::string path = Scratch("las.nrrd");
  std::vector<float> values(3 * 4 * 2);
  for (size_t i = 0; i < values.size(); ++i) values[i] = (float)i;
  WriteFloatNrrd(path,
                 "dimension: 3\nsizes: 3 4 2\nspace: left-anterior-superior\n"
                 "space directions: (1,0,0) (0,2,0) (0,0,3)\nspace origin: (5,6,7)\n",
                 values);
  const HostVolume v = LoadVolume(path);
  ASSERT_EQ(v.dims, (std::array<int, 3>{3, 4, 2}));
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 3; ++i) {
        const int f = (int)ValueAt(v, i, j, k), fi = f % 3, fj = (f / 3) % 4, fk = f / 12;
        ExpectWorld(v, {(float)i, (float)j, (float)k}, {5.f + fi, -(6.f + 2 * fj), 7.f + 3 * fk});
      }
}

// ---------------------------------------------------------------------------
// Errors: each must be an InputError naming the file
// ---------------------------------------------------------------------------

TEST(VolumeLoader, MissingPath) { ExpectInputError(Scratch("does_not_exist.nrrd"), "no such file"); }

TEST(VolumeLoader, UnknownExtension) {
  const std::string path = Scratch("volume.xyz");
  std::ofstream(path) << "not a volume\n";
  ExpectInputError(path, "unknown volume format");
}

TEST(VolumeLoader, TruncatedNrrd) {
  const std::string path = Scratch("headsq_truncated.nrrd");
  CopyTruncated(Data("ct_head_headsq.nrrd"), path, 0.5);
  ExpectInputError(path);
}

TEST(VolumeLoader, TruncatedInv3) {
  if (!fs::exists(mmrtm::DefaultVolumePath()))
    GTEST_SKIP() << mmrtm::DefaultVolumePath() << " is absent (Debian package invesalius-examples)";
  for (double fraction : {0.0005, 0.5, 0.99}) {
    SCOPED_TRACE(fraction);
    const std::string path = Scratch("cranium_truncated.inv3");
    CopyTruncated(mmrtm::DefaultVolumePath(), path, fraction);
    ExpectInputError(path);
  }
}

// Readers that only warn on the console (legacy VTK, raw NRRD, MetaImage)
// must still fail on short files.
TEST(VolumeLoader, TruncatedCopiesOfOtherFormats) {
  for (const char* name : {"fuel.nii.gz", "hydrogen.vti", "iron_protein.vtk", "carotid_flow.vtk"}) {
    const std::string path = Scratch(std::string("truncated_") + name);
    CopyTruncated(Data(name), path, 0.5);
    ExpectInputError(path);
  }
  // MetaImage: the header intact, its compressed data file cut short.
  const std::string folder = Scratch("truncated_mhd");
  fs::create_directories(folder);
  fs::copy_file(Data("frogtissue.mhd"), folder + "/frogtissue.mhd");
  CopyTruncated(Data("frogtissue.zraw"), folder + "/frogtissue.zraw", 0.9);
  ExpectInputError(folder + "/frogtissue.mhd", "truncated");
  // Raw NRRD with fewer bytes than its sizes need.
  const std::string raw = Scratch("short_raw.nrrd");
  WriteFloatNrrd(raw, "dimension: 3\nsizes: 20 20 20\n", std::vector<float>(1000, 1.f));
  ExpectInputError(raw);
}

// A header that promises more than this machine holds is refused before the
// reader allocates anything (vtkNrrdReader would try, and fail or swap).
TEST(VolumeLoader, VolumeTooLargeForMemoryIsRefusedBeforeAllocating) {
  const std::string path = Scratch("huge.nrrd");
  WriteFloatNrrd(path, "dimension: 3\nsizes: 100000 100000 100000\n", std::vector<float>(64, 1.f));
  // The header's promise is checked against the file before the memory.
  ExpectInputError(path, "the header promises 3.6 PiB of voxels but the file holds 256 bytes");
  ExpectInputError(path, "nothing was allocated");
}

// Copies the frog label map into a scratch folder with one header line
// edited; returns the header's path.
std::string CopyFrogWithHeaderEdit(const std::string& folder, const std::string& from, const std::string& to) {
  const std::string dir = Scratch(folder);
  fs::create_directories(dir);
  fs::copy_file(Data("frogtissue.zraw"), dir + "/frogtissue.zraw");
  std::ifstream in(Data("frogtissue.mhd"));
  std::string header((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = header.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) header.replace(at, from.size(), to);
  std::ofstream(dir + "/frogtissue.mhd") << header;
  return dir + "/frogtissue.mhd";
}

// The Whole Frog header once said CompressedDataSize 260020 for a 262087-byte
// stream, and ITK read garbage into the last slices. Here the whole stream is
// read and checked, with a warning about the header.
TEST(VolumeLoader, MetaImageWithWrongCompressedSizeWarnsAndReadsEverything) {
  const std::string header =
      CopyFrogWithHeaderEdit("frog", "CompressedDataSize = 262087", "CompressedDataSize = 260020");
  std::vector<std::string> warnings;
  mmrtm::VolumeLoadOptions options;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  const HostVolume wrong = LoadVolume(header, "labels", options);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("CompressedDataSize says 260020 bytes but frogtissue.zraw holds 262087"),
            std::string::npos)
      << warnings[0];
  EXPECT_EQ(wrong.voxels, LoadVolume(Data("frogtissue.mhd")).voxels);
  // The last slice holds tissue labels, not garbage: every value is a label id.
  const auto range = wrong.ValueRange();
  EXPECT_LE(range[1], 29.f);
}

// A MetaImage whose DimSize promises more voxels than its data holds.
TEST(VolumeLoader, MetaImageWithTooFewVoxelsIsRefused) {
  ExpectInputError(CopyFrogWithHeaderEdit("frog_dims", "DimSize = 500 470 136", "DimSize = 500 470 140"), "expected");
}

// A NaN voxel (a hole in a simulation) is read as the volume's least value,
// and counted for the caller's warning; an infinite one stays an error.
// Catches a NaN passed on to the tracer (no image) or refused.
TEST(VolumeLoader, NanVoxelIsTheLeastValueAndInfinityIsRejected) {
  const std::string path = Scratch("nan.nrrd");
  std::vector<float> values(3 * 2 * 2, 2.f);
  values[2] = -1.f;
  values[7] = std::numeric_limits<float>::quiet_NaN();
  WriteFloatNrrd(path, "dimension: 3\nsizes: 3 2 2\nspacings: 1 1 1\n", values);
  const HostVolume v = LoadVolume(path, "scalars");
  EXPECT_EQ(v.nanVoxelsReplaced, 1);
  EXPECT_EQ(v.Value(7), -1.f);  // the least value
  values[7] = std::numeric_limits<float>::infinity();
  WriteFloatNrrd(path, "dimension: 3\nsizes: 3 2 2\nspacings: 1 1 1\n", values);
  ExpectInputError(path, "non-finite");
}

// The voxel types the loaders read in place, as NRRD and MetaImage name them.
struct NativeType {
  const char* nrrd;
  const char* metaImage;
  int size;
  VoxelType voxelType;
};
constexpr NativeType kNativeTypes[] = {{"uchar", "MET_UCHAR", 1, VoxelType::UInt8},
                                       {"short", "MET_SHORT", 2, VoxelType::Int16},
                                       {"ushort", "MET_USHORT", 2, VoxelType::UInt16},
                                       {"float", "MET_FLOAT", 4, VoxelType::Float32}};
constexpr int kRampDims[3] = {37, 11, 5};

// The bytes of a 37 x 11 x 5 ramp 0, 1, 2, ... of `type` (mod its span;
// int16 shifted by -1000, float as 0.25 i - 100), in big or little endian.
std::vector<uint8_t> RampBytes(const NativeType& type, bool bigEndian) {
  const int n = kRampDims[0] * kRampDims[1] * kRampDims[2], size = type.size;
  std::vector<uint8_t> bytes((size_t)n * size);
  for (int i = 0; i < n; ++i) {
    uint8_t* v = bytes.data() + (size_t)i * size;
    if (type.voxelType == VoxelType::Float32) {
      const float f = 0.25f * (float)i - 100.f;
      std::memcpy(v, &f, 4);
    } else {
      const int value = type.voxelType == VoxelType::Int16 ? i - 1000 : i;
      std::memcpy(v, &value, (size_t)size);  // little endian, as this machine is
    }
    if (bigEndian) std::reverse(v, v + size);
  }
  return bytes;
}

// A NRRD of RampBytes as `encoding` (raw or gzip) in `endian` byte order,
// its data attached or in a detached file. Returns the header's path.
std::string WriteNrrdOfType(const std::string& name, const NativeType& type, const std::string& encoding,
                            const std::string& endian, bool detached) {
  const std::string path = Scratch(name + (detached ? ".nhdr" : ".nrrd"));
  const int nx = kRampDims[0], ny = kRampDims[1], nz = kRampDims[2];
  const std::vector<uint8_t> bytes = RampBytes(type, endian == "big");
  const std::string dataName = name + (encoding == "gzip" ? ".raw.gz" : ".raw");
  {
    std::ofstream out(path, std::ios::binary);
    out << "NRRD0004\ntype: " << type.nrrd << "\ndimension: 3\nsizes: " << nx << " " << ny << " " << nz
        << "\nspacings: 1 1 1\nencoding: " << encoding << "\nendian: " << endian << "\n";
    if (detached) out << "data file: " << dataName << "\n";
    out << "\n";
  }
  const std::string dataPath = detached ? (fs::path(path).parent_path() / dataName).string() : path;
  if (detached) fs::remove(dataPath);
  if (encoding == "gzip") {
    gzFile gz = gzopen(dataPath.c_str(), "ab");
    gzwrite(gz, bytes.data(), (unsigned)bytes.size());
    gzclose(gz);
  } else {
    std::ofstream(dataPath, std::ios::binary | std::ios::app)
        .write(reinterpret_cast<const char*>(bytes.data()), (std::streamsize)bytes.size());
  }
  return path;
}

// Raw NRRD data of a native type is read straight into the volume; every
// other encoding still goes through vtkNrrdReader. Both must give the same
// voxels in the same type: catches a wrong data offset (attached or
// detached), bytes not swapped from big endian, and a row order that
// differs from vtkNrrdReader's (which reverses rows and has them put back).
TEST(VolumeLoader, RawNrrdReadDirectlyEqualsTheVtkReadersVoxels) {
  for (const NativeType& t : kNativeTypes) {
    SCOPED_TRACE(t.nrrd);
    const HostVolume reference = LoadVolume(WriteNrrdOfType("gz", t, "gzip", "little", false));
    ASSERT_EQ(reference.type, t.voxelType);
    for (const char* endian : {"little", "big"})
      for (bool detached : {false, true}) {
        SCOPED_TRACE(std::string(endian) + (detached ? " detached" : " attached"));
        const HostVolume v = LoadVolume(WriteNrrdOfType("raw", t, "raw", endian, detached));
        EXPECT_EQ(v.type, t.voxelType);
        EXPECT_EQ(v.dims, reference.dims);
        EXPECT_TRUE(v.voxels == reference.voxels);
      }
  }
}

// A MetaImage of RampBytes: uncompressed (LOCAL in a .mha, or a detached
// .raw) in big endian when `msb`, or zlib-compressed (read by
// vtkMetaImageReader). Returns the header's path.
std::string WriteMetaImageOfType(const std::string& name, const NativeType& type, bool compressed, bool msb,
                                 bool detached) {
  const int nx = kRampDims[0], ny = kRampDims[1], nz = kRampDims[2];
  const std::vector<uint8_t> bytes = RampBytes(type, msb);
  std::vector<uint8_t> data = bytes;
  if (compressed) {
    uLongf length = compressBound((uLong)bytes.size());
    data.resize(length);
    compress2(data.data(), &length, bytes.data(), (uLong)bytes.size(), 6);
    data.resize(length);
  }
  const std::string path = Scratch(name + (detached ? ".mhd" : ".mha"));
  const std::string dataName = name + (compressed ? ".zraw" : ".raw");
  std::ofstream out(path, std::ios::binary);
  out << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = " << (msb ? "True" : "False")
      << "\nCompressedData = " << (compressed ? "True" : "False") << "\n";
  if (compressed) out << "CompressedDataSize = " << data.size() << "\n";
  out << "ElementSpacing = 0.5 0.75 2\nOffset = 10 20 30\nDimSize = " << nx << " " << ny << " " << nz
      << "\nElementType = " << type.metaImage << "\nElementDataFile = " << (detached ? dataName : "LOCAL") << "\n";
  if (detached) {
    out.close();
    std::ofstream((fs::path(path).parent_path() / dataName).string(), std::ios::binary)
        .write(reinterpret_cast<const char*>(data.data()), (std::streamsize)data.size());
  } else {
    out.write(reinterpret_cast<const char*>(data.data()), (std::streamsize)data.size());
  }
  return path;
}

// Uncompressed MetaImage data of a native type is read straight into the
// volume; compressed data goes through vtkMetaImageReader. Both give the
// same voxels, type and geometry: catches a wrong data offset (LOCAL after
// the header, or a detached file), bytes not swapped from big endian, and
// geometry that came from VTK's image before.
TEST(VolumeLoader, RawMetaImageReadDirectlyEqualsTheVtkReadersVoxels) {
  for (const NativeType& t : kNativeTypes) {
    SCOPED_TRACE(t.metaImage);
    const HostVolume reference = LoadVolume(WriteMetaImageOfType("z", t, true, false, true));
    ASSERT_EQ(reference.type, t.voxelType);
    for (bool msb : {false, true})
      for (bool detached : {false, true}) {
        SCOPED_TRACE(std::string(msb ? "MSB" : "LSB") + (detached ? " detached" : " LOCAL"));
        const HostVolume v = LoadVolume(WriteMetaImageOfType("raw", t, false, msb, detached));
        EXPECT_EQ(v.type, t.voxelType);
        EXPECT_EQ(v.dims, reference.dims);
        EXPECT_TRUE(v.voxels == reference.voxels);
        ExpectWorld(v, {1, 2, 3}, {10.5f, 21.5f, 36.f});
        ExpectWorld(reference, {1, 2, 3}, {10.5f, 21.5f, 36.f});
      }
  }
}

// A raw data file shorter than its header's sizes, and a gzip stream cut
// short: errors that name the file, no volume.
TEST(VolumeLoader, ShortRawDataFileAndTruncatedGzipStreamAreErrors) {
  const std::string detached = WriteNrrdOfType("short_detached", kNativeTypes[1], "raw", "little", true);
  const std::string data = (fs::path(detached).parent_path() / "short_detached.raw").string();
  fs::resize_file(data, fs::file_size(data) - 2);
  ExpectInputError(detached, "short_detached.raw");
  const std::string gz = WriteNrrdOfType("cut_gzip", kNativeTypes[1], "gzip", "little", false);
  fs::resize_file(gz, fs::file_size(gz) - 40);
  ExpectInputError(gz);
}

// Loading reports its progress: fractions that never go back and end at 1,
// for the direct raw read and for a VTK reader's (gzip) read.
TEST(VolumeLoader, LoadingReportsProgressUpToOne) {
  for (const char* encoding : {"raw", "gzip"}) {
    SCOPED_TRACE(encoding);
    std::vector<double> fractions;
    mmrtm::VolumeLoadOptions options;
    options.progress = [&](double f) { fractions.push_back(f); };
    LoadVolume(WriteNrrdOfType("progress", kNativeTypes[1], encoding, "little", false), "scalars", options);
    ASSERT_FALSE(fractions.empty());
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
  }
}

TEST(VolumeLoader, DefaultVolumePath) {
  EXPECT_EQ(mmrtm::DefaultVolumePath(), "/usr/share/doc/invesalius-examples/examples/Cranium.inv3");
}

}  // namespace
