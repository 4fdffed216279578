// Image tests: real CTs from ../shared/data with the ct-bone preset, against
// baselines that were looked at (Data/Baselines/*.png): the head CT, and the
// chest DICOM series in its own orientation (read through the DICOM loader).
//
// The comparison is statistical (ImageAgreement.h): the test's image is the
// mean of kReplicates independent renders (other seeds: independently
// scrambled Sobol' nets), whose spread gives each pixel's error; the
// baseline keeps its mean and that variance (PFM) from kBaselineReplicates
// renders. Two unbiased images of the scene fail with probability below
// 1e-4, so the baseline stays valid for any seed and any unbiased change of
// the estimator; a change of a channel's mean over the covered pixels by
// the comparison's power fails with probability 1 - 1e-4. The test asserts
// a power of at most 2 % (0.8 % measured) and shows it: a bone albedo 3 %
// lower fails, and so does the image made 2 % darker.
//
// MMRTM_UPDATE_BASELINES=1 rewrites the baseline instead of comparing; look at
// the PNG before committing it, and name it and the reason in the commit. A
// baseline needs remaking only when the image is meant to change.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "ExpectAgreement.h"
#include "ReplicateRenders.h"
#include "image_io.h"
#include "mmrtmVolumeLoader.h"
#include "scene_json.h"
#include "TestOutputFolder.h"

namespace mmrtm {
namespace {

constexpr int kReplicates = 8, kSpp = 8;
constexpr int kBaselineReplicates = 32, kBaselineSpp = 16;

struct Rendered {
  test::ImageEstimate estimate;
  std::vector<uint8_t> png;
  float meanAlpha = 0;
};

// The ct-bone preset on `volume` (a file or folder in ../shared/data),
// 128 x 128, `replicates` renders of `spp` samples from seed firstSeed on.
Rendered RenderBonePreset(const std::string& volume, const nlohmann::json& camera, uint64_t firstSeed, int replicates,
                          int spp, float albedoScale = 1.f) {
  nlohmann::json doc = ReadJsonFile(std::string(MMRTM_DATA_DIR) + "/presets/ct-bone.json");
  doc["render"].merge_patch({{"width", 128}, {"height", 128}});
  for (auto& c : doc["materials"]["bone"]["albedo"]) c = c.get<float>() * albedoScale;
  doc["camera"].merge_patch(camera);
  SceneInputs inputs;
  inputs.volumes["scalars"] = LoadVolume(std::string(MMRTM_SHARED_DATA_DIR) + "/" + volume);
  Scene scene = SceneFromJson(doc, std::move(inputs));
  const SceneView view = scene.Build();
  Rendered r;
  Film all(1, 1);
  r.estimate = test::RenderReplicates(view, replicates, spp, firstSeed, nullptr, &all);
  for (int y = 0; y < all.Height(); ++y)
    for (int x = 0; x < all.Width(); ++x) r.meanAlpha += all.Alpha(x, y);
  r.meanAlpha /= (float)(all.Width() * all.Height());
  r.png = all.ToneMapped(scene.render.exposure, scene.render.toneMapper);
  return r;
}

RGBImage Channels(const test::ImageEstimate& e, const std::vector<double>& values) {
  RGBImage image{e.width, e.height, {}};
  for (size_t p = 0; p < (size_t)e.width * e.height; ++p)
    image.pixels.emplace_back((float)values[3 * p], (float)values[3 * p + 1], (float)values[3 * p + 2]);
  return image;
}

void WriteBaseline(const std::string& baseline, const Rendered& r) {
  WritePFM(baseline + ".pfm", Channels(r.estimate, r.estimate.mean));
  WritePFM(baseline + "_variance.pfm", Channels(r.estimate, r.estimate.variance));
  WritePNG(baseline + ".png", r.estimate.width, r.estimate.height, 3, r.png);
  std::ofstream(baseline + ".json")
      << nlohmann::json{{"replicates", kBaselineReplicates}, {"samples_per_replicate", kBaselineSpp}}.dump(2) << "\n";
}

test::ImageEstimate ReadBaseline(const std::string& baseline) {
  const RGBImage mean = ReadPFM(baseline + ".pfm"), variance = ReadPFM(baseline + "_variance.pfm");
  test::ImageEstimate e;
  e.width = mean.width;
  e.height = mean.height;
  e.degreesOfFreedom = ReadJsonFile(baseline + ".json").at("replicates").get<double>() - 1;
  for (size_t p = 0; p < mean.pixels.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      e.mean.push_back(mean.pixels[p][c]);
      e.variance.push_back(variance.pixels[p][c]);
    }
  return e;
}

// The test's estimate readied for a comparison with a baseline of many more
// samples (FloorVarianceByReference: rare paths its replicates all miss).
test::ImageEstimate AgainstBaseline(test::ImageEstimate e, const test::ImageEstimate& baseline) {
  test::FloorVarianceByReference(e, baseline, kReplicates * kSpp, kBaselineReplicates * kBaselineSpp);
  return e;
}

// This NRRD keeps InVesalius's row order with an identity direction, so its
// face is at +y: look from there.
Rendered RenderCranium(uint64_t firstSeed, float albedoScale = 1.f, int replicates = kReplicates, int spp = kSpp) {
  return RenderBonePreset("ct_head_cranium.nrrd", {{"azimuth", 205}}, firstSeed, replicates, spp, albedoScale);
}
Rendered RenderChest(uint64_t firstSeed, int replicates = kReplicates, int spp = kSpp) {
  return RenderBonePreset("ct_chest_dicom", nlohmann::json::object(), firstSeed, replicates, spp);
}

std::string BaselinePath(const std::string& name) { return std::string(MMRTM_DATA_DIR) + "/Baselines/" + name; }

// Checks the image is neither black nor blown out, and compares it with the
// baseline `name` (or rewrites the baseline with MMRTM_UPDATE_BASELINES=1,
// from `baselineRender`, which renders kBaselineReplicates other seeds).
void ExpectMatchesBaseline(const Rendered& r, const std::string& name,
                           const std::function<Rendered()>& baselineRender) {
  const std::string baseline = BaselinePath(name);
  const std::string out = (TestOutputFolder() / (name + ".png")).string();
  WritePNG(out, r.estimate.width, r.estimate.height, 3, r.png);

  // Not a black or blown-out image: the skull covers part of the frame, and
  // the mean luminance is mid-range.
  EXPECT_GT(r.meanAlpha, 0.15f) << out;
  EXPECT_LT(r.meanAlpha, 0.8f) << out;
  double lum = 0;
  for (size_t p = 0; p < r.estimate.mean.size(); p += 3)
    lum += Luminance(RGB((float)r.estimate.mean[p], (float)r.estimate.mean[p + 1], (float)r.estimate.mean[p + 2]));
  lum /= (double)r.estimate.width * r.estimate.height;
  EXPECT_GT(lum, 0.1) << out;
  EXPECT_LT(lum, 0.9) << out;

  if (std::getenv("MMRTM_UPDATE_BASELINES")) {
    WriteBaseline(baseline, baselineRender());
    GTEST_SKIP() << "baseline rewritten: look at " << baseline << ".png before committing it";
  }
  const test::ImageEstimate reference = ReadBaseline(baseline);
  test::ExpectAgreement(name + " against its baseline (see " + out + ")", AgainstBaseline(r.estimate, reference),
                        reference);
}

TEST(ImageCT, HeadBonePresetMatchesBaseline) {
  ExpectMatchesBaseline(RenderCranium(1), "ct_head_cranium_bone",
                        [] { return RenderCranium(1000, 1.f, kBaselineReplicates, kBaselineSpp); });
}

// The chest series through the DICOM loader, seen from the front (the preset's
// default camera, anterior in LPS): a wrong row order, slice order or
// orientation turns or mirrors the ribcage and fails the comparison.
TEST(ImageCT, ChestDicomSeriesMatchesBaseline) {
  ExpectMatchesBaseline(RenderChest(1), "ct_chest_dicom_bone",
                        [] { return RenderChest(1000, kBaselineReplicates, kBaselineSpp); });
}

// The comparison's power, shown: a bone albedo 3 % lower fails, and so does
// the image made 2 % darker.
TEST(ImageCT, ComparisonSeesSmallBiases) {
  const test::ImageEstimate baseline = ReadBaseline(BaselinePath("ct_head_cranium_bone"));
  test::ExpectDisagreement("bone albedo x0.97", AgainstBaseline(RenderCranium(99, 0.97f).estimate, baseline), baseline);
  test::ExpectDisagreement("2 % darker", AgainstBaseline(test::Scaled(RenderCranium(199).estimate, 0.98), baseline),
                           baseline);
}

}  // namespace
}  // namespace mmrtm
