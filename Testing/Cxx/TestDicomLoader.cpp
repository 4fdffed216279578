// Tests of the ITK/GDCM DICOM reader: the real series in ../shared/data load
// with the geometry their headers give (read here with GDCM directly, not
// through the loader), and damaged copies made in a scratch folder (a slice
// dropped, truncated, shuffled, tilted, another pixel spacing, two series in
// one folder) give a clear error or a documented warning, never a crash.
#include <gtest/gtest.h>

#include <gdcmAttribute.h>
#include <gdcmReader.h>
#include <gdcmWriter.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
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
using mmrtm::VolumeLoadOptions;
using mmrtm::VoxelType;

namespace {

std::string Data(const std::string& name) { return std::string(MMRTM_SHARED_DATA_DIR) + "/" + name; }

// A fresh, empty folder in the test's own output folder.
std::string ScratchFolder(const std::string& name) {
  const fs::path dir = TestOutputFolder() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::vector<fs::path> SeriesFiles(const std::string& folder) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(Data(folder))) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

void CopyAll(const std::vector<fs::path>& files, const std::string& to) {
  for (const fs::path& f : files) fs::copy_file(f, fs::path(to) / f.filename());
}

// What a file's header says, read with GDCM (independent of the loader).
struct Header {
  std::array<double, 3> position;
  std::array<double, 6> orientation;
  std::array<double, 2> pixelSpacing;
  double slope = 1, intercept = 0;
};

Header ReadHeader(const fs::path& file) {
  gdcm::Reader reader;
  reader.SetFileName(file.string().c_str());
  EXPECT_TRUE(reader.Read()) << file;
  const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
  Header h;
  gdcm::Attribute<0x0020, 0x0032> ipp;
  ipp.Set(ds);
  gdcm::Attribute<0x0020, 0x0037> iop;
  iop.Set(ds);
  gdcm::Attribute<0x0028, 0x0030> spacing;
  spacing.Set(ds);
  for (int i = 0; i < 3; ++i) h.position[i] = ipp[i];
  for (int i = 0; i < 6; ++i) h.orientation[i] = iop[i];
  for (int i = 0; i < 2; ++i) h.pixelSpacing[i] = spacing[i];
  if (ds.FindDataElement(gdcm::Tag(0x0028, 0x1053))) {
    gdcm::Attribute<0x0028, 0x1053> slope;
    slope.Set(ds);
    h.slope = slope.GetValue();
  }
  if (ds.FindDataElement(gdcm::Tag(0x0028, 0x1052))) {
    gdcm::Attribute<0x0028, 0x1052> intercept;
    intercept.Set(ds);
    h.intercept = intercept.GetValue();
  }
  return h;
}

// Rewrites one string element of a DICOM file (value padded to even length).
void RewriteElement(const fs::path& file, gdcm::Tag tag, std::string value) {
  gdcm::Reader reader;
  reader.SetFileName(file.string().c_str());
  ASSERT_TRUE(reader.Read()) << file;
  if (value.size() % 2) value += ' ';
  gdcm::DataElement element = reader.GetFile().GetDataSet().GetDataElement(tag);
  element.SetByteValue(value.data(), (uint32_t)value.size());
  reader.GetFile().GetDataSet().Replace(element);
  gdcm::Writer writer;
  writer.SetFile(reader.GetFile());
  writer.SetFileName(file.string().c_str());
  ASSERT_TRUE(writer.Write()) << file;
}

std::string Join(const std::vector<double>& v) {
  std::string s;
  for (double x : v) {
    char t[32];
    std::snprintf(t, sizeof t, "%.6f", x);
    s += (s.empty() ? "" : "\\") + std::string(t);
  }
  return s;
}

// The headers of a series, sorted along the slice normal.
std::vector<std::pair<fs::path, Header>> SortedHeaders(const std::string& folder) {
  std::vector<std::pair<fs::path, Header>> list;
  for (const fs::path& f : SeriesFiles(folder)) list.push_back({f, ReadHeader(f)});
  const auto& o = list.front().second.orientation;
  const std::array<double, 3> n{o[1] * o[5] - o[2] * o[4], o[2] * o[3] - o[0] * o[5], o[0] * o[4] - o[1] * o[3]};
  auto along = [&](const Header& h) { return h.position[0] * n[0] + h.position[1] * n[1] + h.position[2] * n[2]; };
  std::sort(list.begin(), list.end(), [&](const auto& a, const auto& b) { return along(a.second) < along(b.second); });
  return list;
}

void ExpectWorld(const HostVolume& v, Vec3 index, std::array<double, 3> expected, double tolerance = 2e-3) {
  const Vec3 w = v.indexToWorld.ApplyPoint(index);
  SCOPED_TRACE(v.source + " index (" + std::to_string(index.x) + ", " + std::to_string(index.y) + ", " +
               std::to_string(index.z) + ")");
  EXPECT_NEAR(w.x, expected[0], tolerance);
  EXPECT_NEAR(w.y, expected[1], tolerance);
  EXPECT_NEAR(w.z, expected[2], tolerance);
}

// The geometry of a loaded series against its headers: the first sorted
// slice is index 0 at its ImagePositionPatient, the last is index n-1, and
// the in-plane axes follow ImageOrientationPatient x PixelSpacing.
void ExpectGeometryFromHeaders(const HostVolume& v, const std::string& folder) {
  const auto headers = SortedHeaders(folder);
  const Header& first = headers.front().second;
  const Header& last = headers.back().second;
  ASSERT_EQ(v.dims[2], (int)headers.size());
  ExpectWorld(v, {0, 0, 0}, first.position);
  ExpectWorld(v, {0, 0, (float)(v.dims[2] - 1)}, last.position);
  const auto& o = first.orientation;
  const double dx = first.pixelSpacing[1], dy = first.pixelSpacing[0];
  ExpectWorld(
      v, {10, 0, 0},
      {first.position[0] + 10 * dx * o[0], first.position[1] + 10 * dx * o[1], first.position[2] + 10 * dx * o[2]});
  ExpectWorld(
      v, {0, 10, 0},
      {first.position[0] + 10 * dy * o[3], first.position[1] + 10 * dy * o[4], first.position[2] + 10 * dy * o[5]});
}

// Loads with warnings collected instead of printed.
HostVolume LoadCollecting(const std::string& folder, std::vector<std::string>& warnings,
                          const std::string& series = "") {
  VolumeLoadOptions options;
  options.series = series;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  return LoadVolume(folder, "scalars", options);
}

void ExpectInputError(const std::string& folder, const std::string& text, const std::string& series = "") {
  SCOPED_TRACE(folder);
  try {
    VolumeLoadOptions options;
    options.series = series;
    options.warn = [](const std::string&) {};
    LoadVolume(folder, "scalars", options);
    ADD_FAILURE() << "no InputError for " << folder;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(folder), std::string::npos) << msg;
    EXPECT_NE(msg.find(text), std::string::npos) << "expected '" << text << "' in: " << msg;
  }
}

bool Contains(const std::vector<std::string>& warnings, const std::string& text) {
  for (const std::string& w : warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

float ValueAt(const HostVolume& v, int i, int j, int k) {
  return v.Value(i + (int64_t)v.dims[0] * (j + (int64_t)v.dims[1] * k));
}

// ---------------------------------------------------------------------------
// The real series
// ---------------------------------------------------------------------------

TEST(DicomLoader, ChestSeriesGeometryAndHounsfieldUnits) {
  std::vector<std::string> warnings;
  const HostVolume v = LoadCollecting(Data("ct_chest_dicom"), warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_EQ(v.dims, (std::array<int, 3>{512, 512, 92}));
  EXPECT_EQ(v.type, VoxelType::Int16);  // uint16 stored, intercept -1000: int16 holds every value
  ExpectGeometryFromHeaders(v, "ct_chest_dicom");
  const Header h = ReadHeader(Data("ct_chest_dicom/000197.dcm"));
  EXPECT_EQ(h.intercept, -1000.0);
  const auto range = v.ValueRange();
  EXPECT_GE(range[0], -1024.f);  // air in HU, not the stored 0
  EXPECT_GT(range[1], 1000.f);   // bone
}

// JPEG 2000 lossless, 20 slices 2 mm apart (SliceThickness says 3: the
// positions decide), rescale intercept -1024.
TEST(DicomLoader, Jpeg2000SeriesDecodes) {
  std::vector<std::string> warnings;
  const HostVolume v = LoadCollecting(Data("ct_abdomen_dicom_j2k"), warnings);
  EXPECT_EQ(v.dims, (std::array<int, 3>{512, 512, 20}));
  EXPECT_EQ(v.type, VoxelType::Int16);
  ExpectGeometryFromHeaders(v, "ct_abdomen_dicom_j2k");
  const Vec3 step = v.indexToWorld.ApplyVector({0, 0, 1});
  EXPECT_NEAR(std::sqrt(step.x * step.x + step.y * step.y + step.z * step.z), 2.0, 1e-3);
  const auto range = v.ValueRange();
  EXPECT_LT(range[0], -900.f);  // air
  EXPECT_GT(range[1], 500.f);   // bone or contrast
  // Not noise: the centre of the body is soft tissue (-200..200 HU) in most slices.
  int soft = 0;
  for (int k = 0; k < 20; ++k) soft += std::abs(ValueAt(v, 256, 300, k)) < 200.f;
  EXPECT_GT(soft, 10);
}

TEST(DicomLoader, ListsSeries) {
  const auto list = mmrtm::ListDicomSeries(Data("ct_chest_dicom"));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].slices, 92);
  EXPECT_EQ(list[0].modality, "CT");
  EXPECT_EQ(list[0].uid, "1.3.6.1.4.1.14519.5.2.1.6279.6001.154677396354641150280013275227");
}

// ---------------------------------------------------------------------------
// Copies that the tests damage
// ---------------------------------------------------------------------------

// File names say nothing about order: the positions do.
TEST(DicomLoader, ShuffledFileNamesGiveTheSameVolume) {
  const std::string folder = ScratchFolder("shuffled");
  std::vector<fs::path> files = SeriesFiles("ct_abdomen_dicom_j2k");
  std::vector<int> order(files.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = (int)i;
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (size_t i = 0; i < files.size(); ++i)
    fs::copy_file(files[i], fs::path(folder) / ("slice" + std::to_string(order[i]) + ".dcm"));
  const HostVolume original = LoadVolume(Data("ct_abdomen_dicom_j2k"));
  const HostVolume shuffled = LoadVolume(folder);
  EXPECT_EQ(shuffled.voxels, original.voxels);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(shuffled.indexToWorld.m[r][c], original.indexToWorld.m[r][c]);
}

// Slices are decoded one at a time into the smallest exact type. When a
// later slice holds values that type cannot (a rescale intercept moved to
// +40000: above int16, with air below 0), the slices stored before are
// widened: the volume becomes float, every value exact. Catches slices
// stored into the narrow type before the widening (wrapped values), and
// the widening converting the earlier slices wrongly. Loading reports its
// progress slice by slice, up to 1.
TEST(DicomLoader, ASliceBeyondTheFirstSlicesTypeWidensTheWholeVolume) {
  const std::string folder = ScratchFolder("widened");
  const auto headers = SortedHeaders("ct_chest_dicom");
  for (size_t i = 0; i < headers.size(); ++i) {
    const fs::path copy = fs::path(folder) / headers[i].first.filename();
    fs::copy_file(headers[i].first, copy);
    if (i >= 60) RewriteElement(copy, gdcm::Tag(0x0028, 0x1052), "40000");
  }
  std::vector<double> fractions;
  VolumeLoadOptions options;
  options.progress = [&](double f) { fractions.push_back(f); };
  const HostVolume v = LoadVolume(folder, "scalars", options);
  const HostVolume original = LoadVolume(Data("ct_chest_dicom"));
  ASSERT_EQ(original.type, VoxelType::Int16);
  EXPECT_EQ(v.type, VoxelType::Float32);
  ASSERT_EQ(v.dims, original.dims);
  for (auto [i, j] : {std::pair{0, 0}, std::pair{256, 256}, std::pair{100, 300}, std::pair{400, 200}})
    for (int k : {0, 30, 59, 60, 91}) {
      SCOPED_TRACE("voxel " + std::to_string(i) + ", " + std::to_string(j) + ", " + std::to_string(k));
      EXPECT_EQ(ValueAt(v, i, j, k), ValueAt(original, i, j, k) + (k >= 60 ? 41000.f : 0.f));
    }
  EXPECT_EQ(fractions.size(), headers.size());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_EQ(fractions.back(), 1.0);
}

// A missing slice: resampled onto the regular grid, with a warning; the
// missing slice is the average of its neighbours (halfway between them).
TEST(DicomLoader, MissingSliceIsResampledWithAWarning) {
  const std::string folder = ScratchFolder("missing_slice");
  const auto headers = SortedHeaders("ct_chest_dicom");
  for (size_t i = 0; i < headers.size(); ++i)
    if (i != 40) fs::copy_file(headers[i].first, fs::path(folder) / headers[i].first.filename());
  std::vector<std::string> warnings;
  const HostVolume v = LoadCollecting(folder, warnings);
  ASSERT_TRUE(Contains(warnings, "not evenly spaced")) << (warnings.empty() ? "no warning" : warnings[0]);
  EXPECT_TRUE(Contains(warnings, headers[39].first.filename().string()));  // the gap is named
  EXPECT_EQ(v.dims[2], 92);
  EXPECT_EQ(v.type, VoxelType::Int16);
  ExpectWorld(v, {0, 0, 91}, headers.back().second.position);
  const HostVolume full = LoadVolume(Data("ct_chest_dicom"));
  for (auto [i, j] : {std::pair{256, 256}, std::pair{100, 300}, std::pair{400, 200}}) {
    EXPECT_EQ(ValueAt(v, i, j, 39), ValueAt(full, i, j, 39));
    EXPECT_EQ(ValueAt(v, i, j, 41), ValueAt(full, i, j, 41));
    EXPECT_NEAR(ValueAt(v, i, j, 40), 0.5f * (ValueAt(full, i, j, 39) + ValueAt(full, i, j, 41)), 0.5f);
  }
}

// A gantry tilt: every slice shifted sideways in proportion to its height.
// The grid carries the shear, so each slice stays at its position.
TEST(DicomLoader, GantryTiltBecomesAShearWithAWarning) {
  const std::string folder = ScratchFolder("tilted");
  auto headers = SortedHeaders("ct_chest_dicom");  // uncompressed: GDCM rewrites it
  headers.resize(16);
  const double tiltDegrees = 15.0, shear = std::tan(tiltDegrees * M_PI / 180.0);
  const double z0 = headers.front().second.position[2];
  std::vector<std::array<double, 3>> positions;
  for (const auto& [file, h] : headers) {
    const fs::path copy = fs::path(folder) / file.filename();
    fs::copy_file(file, copy);
    std::array<double, 3> p = h.position;
    p[1] += shear * (p[2] - z0);
    positions.push_back(p);
    RewriteElement(copy, gdcm::Tag(0x0020, 0x0032), Join({p[0], p[1], p[2]}));
  }
  std::vector<std::string> warnings;
  const HostVolume v = LoadCollecting(folder, warnings);
  ASSERT_TRUE(Contains(warnings, "tilted by 15.00 degrees")) << (warnings.empty() ? "no warning" : warnings[0]);
  EXPECT_EQ(v.dims[2], (int)headers.size());
  ExpectWorld(v, {0, 0, 0}, positions.front());
  ExpectWorld(v, {0, 0, (float)(v.dims[2] - 1)}, positions.back());
  ExpectWorld(v, {7, 9, 10},
              {positions[10][0] + 7 * headers[0].second.pixelSpacing[1],
               positions[10][1] + 9 * headers[0].second.pixelSpacing[0], positions[10][2]});
  const HostVolume untilted = LoadVolume(Data("ct_chest_dicom"));
  for (int k : {0, 15})
    for (auto [i, j] : {std::pair{256, 256}, std::pair{100, 300}})
      EXPECT_EQ(ValueAt(v, i, j, k), ValueAt(untilted, i, j, k));  // no resampling
}

TEST(DicomLoader, TwoSeriesInOneFolder) {
  const std::string folder = ScratchFolder("two_series");
  CopyAll(SeriesFiles("ct_chest_dicom"), folder);
  CopyAll(SeriesFiles("ct_abdomen_dicom_j2k"), folder);
  EXPECT_EQ(mmrtm::ListDicomSeries(folder).size(), 2u);
  // The largest by default, with a warning listing both.
  std::vector<std::string> warnings;
  const HostVolume chest = LoadCollecting(folder, warnings);
  EXPECT_EQ(chest.dims[2], 92);
  ASSERT_TRUE(Contains(warnings, "holds 2 series"));
  EXPECT_TRUE(Contains(warnings, "CT Body 3.0"));
  // Another by its description (case-insensitive) or UID.
  EXPECT_EQ(LoadCollecting(folder, warnings, "ct body 3.0").dims[2], 20);
  EXPECT_EQ(
      LoadCollecting(folder, warnings, "1.3.6.1.4.1.14519.5.2.1.6279.6001.154677396354641150280013275227").dims[2], 92);
  ExpectInputError(folder, "no series with the UID or description \"nonsense\"", "nonsense");
}

TEST(DicomLoader, InconsistentPixelSpacingIsRefused) {
  const std::string folder = ScratchFolder("pixel_spacing");
  auto files = SeriesFiles("ct_chest_dicom");  // uncompressed: GDCM rewrites it
  files.resize(10);
  CopyAll(files, folder);
  const fs::path changed = fs::path(folder) / files[5].filename();
  RewriteElement(changed, gdcm::Tag(0x0028, 0x0030), "0.5\\0.5");
  ExpectInputError(folder, "inconsistent pixel spacing");
  ExpectInputError(folder, changed.filename().string());
}

TEST(DicomLoader, TruncatedSliceIsNamed) {
  for (const char* series : {"ct_chest_dicom", "ct_abdomen_dicom_j2k"}) {  // uncompressed, JPEG 2000
    const std::string folder = ScratchFolder(std::string("truncated_") + series);
    const auto files = SeriesFiles(series);
    CopyAll(files, folder);
    const fs::path cut = fs::path(folder) / files[7].filename();
    fs::resize_file(cut, fs::file_size(cut) / 2);
    ExpectInputError(folder, cut.filename().string());
  }
}

TEST(DicomLoader, DuplicatedSliceIsRefused) {
  const std::string folder = ScratchFolder("duplicate");
  const auto files = SeriesFiles("ct_abdomen_dicom_j2k");
  CopyAll(files, folder);
  fs::copy_file(files[3], fs::path(folder) / "copy.dcm");
  ExpectInputError(folder, "lie at the same position");
}

TEST(DicomLoader, EmptyFolder) { ExpectInputError(ScratchFolder("empty"), "holds no files"); }

TEST(DicomLoader, FolderWithoutDicomFiles) {
  const std::string folder = ScratchFolder("no_dicom");
  std::ofstream(folder + "/notes.txt") << "no images here\n";
  fs::copy_file(Data("mr_head_labels.txt"), fs::path(folder) / "labels.txt");
  ExpectInputError(folder, "none of its 2 file(s) is a DICOM image");
}

TEST(DicomLoader, SeriesOptionWithoutItsSeries) {
  ExpectInputError(Data("ct_chest_dicom"), "the folder holds:\n  1.3.6.1.4.1.14519", "CT Body 3.0");
}

}  // namespace

// ---------------------------------------------------------------------------
// A label map on the DICOM series' voxels
// ---------------------------------------------------------------------------

// Mean HU and count of the CT voxels under label `id`.
std::pair<double, int64_t> MeanUnderLabel(const HostVolume& ct, const HostVolume& labels, int id) {
  double sum = 0;
  int64_t n = 0;
  for (int64_t i = 0; i < ct.VoxelCount(); ++i)
    if (labels.Value(i) == (float)id) sum += ct.Value(i), ++n;
  return {n ? sum / n : 0.0, n};
}

// TotalSegmentator's NIfTI labels of the JPEG 2000 series lie on another
// voxel order than the DICOM grid (NIfTI is stored RAS-first): aligned in
// world space, the liver's voxels hold liver HU (about 40-120) and the
// aorta's contrast-free blood too; taken voxel by voxel without alignment,
// they do not.
TEST(DicomLoader, LabelMapAlignsToTheSeriesInWorldSpace) {
  const HostVolume ct = LoadVolume(Data("ct_abdomen_dicom_j2k"));
  const HostVolume raw =
      LoadVolume(Data("ct_abdomen_dicom_j2k_labels.nii.gz"), "labels", mmrtm::Interpolation::Nearest);
  ASSERT_EQ(raw.dims, ct.dims);
  bool resampled = false;
  const HostVolume aligned = mmrtm::AlignLabelsToVolume(raw, ct, &resampled);
  EXPECT_TRUE(resampled);
  const auto [liverHU, liverVoxels] = MeanUnderLabel(ct, aligned, 5);
  const auto [spleenHU, spleenVoxels] = MeanUnderLabel(ct, aligned, 1);
  std::printf("aligned: liver %.1f HU over %lld voxels, spleen %.1f HU over %lld voxels\n", liverHU,
              (long long)liverVoxels, spleenHU, (long long)spleenVoxels);
  EXPECT_GT(liverVoxels, 10000);
  EXPECT_GT(liverHU, 30.0);
  EXPECT_LT(liverHU, 150.0);
  EXPECT_GT(spleenHU, 30.0);
  EXPECT_LT(spleenHU, 150.0);
  const auto [naiveHU, naiveVoxels] = MeanUnderLabel(ct, raw, 5);
  std::printf("voxel by voxel: liver %.1f HU over %lld voxels\n", naiveHU, (long long)naiveVoxels);
  EXPECT_TRUE(naiveHU < 30.0 || naiveHU > 150.0) << "the test would pass without alignment";
}
