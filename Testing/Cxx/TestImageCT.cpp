// Image tests: real CTs from ../shared/data with the ct-bone preset, against
// baselines that were looked at (Data/Baselines/*.png): the head CT, and the
// chest DICOM series in its own orientation (read through the DICOM loader).
//
// The baseline keeps each pixel's mean and the variance of that mean (PFM),
// so the comparison is statistical: the difference of two Monte Carlo images
// of the same scene has variance var_a + var_b, and its z-scores must look
// like noise. This passes for any seed and fails for a change of the image
// (brightness, a TF, a broken estimator) rather than of the noise pattern.
//
// MMRTM_UPDATE_BASELINES=1 rewrites the baseline instead of comparing; look at
// the PNG before committing it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "cpu_renderer.h"
#include "image_io.h"
#include "mmrtmVolumeLoader.h"
#include "scene_json.h"

namespace mmrtm {
namespace {

namespace fs = std::filesystem;

struct Rendered {
  RGBImage mean, variance;
  std::vector<uint8_t> png;
  float meanAlpha = 0;
};

// The ct-bone preset on `volume` (a file or folder in ../shared/data), 128 x 128.
Rendered RenderBonePreset(const std::string& volume, const nlohmann::json& camera, uint64_t seed,
                          float albedoScale = 1.f) {
  nlohmann::json doc = ReadJsonFile(std::string(MMRTM_DATA_DIR) + "/presets/ct-bone.json");
  doc["render"].merge_patch({{"width", 128}, {"height", 128}, {"spp", 32}, {"seed", seed}});
  for (auto& c : doc["materials"]["bone"]["albedo"]) c = c.get<float>() * albedoScale;
  doc["camera"].merge_patch(camera);
  SceneInputs inputs;
  inputs.volumes["scalars"] = LoadVolume(std::string(MMRTM_SHARED_DATA_DIR) + "/" + volume);
  Scene scene = SceneFromJson(doc, std::move(inputs));
  SceneView view = scene.Build();
  Film film(scene.render.width, scene.render.height);
  CpuRenderer(2).Render(view, film, scene.render.samplesPerPixel);
  Rendered r;
  r.mean = film.Linear();
  r.variance = RGBImage{film.Width(), film.Height(), {}};
  for (int y = 0; y < film.Height(); ++y)
    for (int x = 0; x < film.Width(); ++x) {
      r.variance.pixels.push_back(film.VarianceOfMean(x, y));
      r.meanAlpha += film.Alpha(x, y);
    }
  r.meanAlpha /= (float)(film.Width() * film.Height());
  r.png = film.ToneMapped(scene.render.exposure, scene.render.toneMapper);
  return r;
}

struct Comparison {
  double meanZ2 = 0;         // over noisy pixels: about 1 for independent seeds, 0 for the same seed
  double fractionOver4 = 0;  // pixels with |z| > 4 in any channel
};

Comparison Compare(const Rendered& a, const RGBImage& baseMean, const RGBImage& baseVar) {
  Comparison c;
  const size_t n = a.mean.pixels.size();
  int over = 0, noisy = 0;
  for (size_t i = 0; i < n; ++i) {
    bool flagged = false;
    for (int ch = 0; ch < 3; ++ch) {
      const double d = a.mean.pixels[i][ch] - baseMean.pixels[i][ch];
      const double v = a.variance.pixels[i][ch] + baseVar.pixels[i][ch];
      // Background pixels see the same sky texel in every sample: no
      // variance, no information; they must simply agree.
      if (v < 1e-9) {
        flagged = flagged || std::fabs(d) > 1e-3;
        continue;
      }
      const double z2 = d * d / v;
      c.meanZ2 += z2;
      ++noisy;
      flagged = flagged || z2 > 16.0;
    }
    over += flagged;
  }
  c.meanZ2 /= std::max(noisy, 1);
  c.fractionOver4 = (double)over / n;
  return c;
}

// This NRRD keeps InVesalius's row order with an identity direction, so its
// face is at +y: look from there.
Rendered RenderCranium(uint64_t seed, float albedoScale = 1.f) {
  return RenderBonePreset("ct_head_cranium.nrrd", {{"azimuth", 205}}, seed, albedoScale);
}

const std::string kBaseline = std::string(MMRTM_DATA_DIR) + "/Baselines/ct_head_cranium_bone";

// Renders, checks the image is neither black nor blown out, and compares it
// with the baseline `name` (or rewrites it with MMRTM_UPDATE_BASELINES=1).
void ExpectMatchesBaseline(const Rendered& r, const std::string& name) {
  const std::string baseline = std::string(MMRTM_DATA_DIR) + "/Baselines/" + name;
  const std::string out = std::string(MMRTM_TEST_OUTPUT_DIR) + "/" + name + ".png";
  WritePNG(out, r.mean.width, r.mean.height, 3, r.png);

  // Not a black or blown-out image: the skull covers part of the frame, and
  // the mean luminance is mid-range.
  EXPECT_GT(r.meanAlpha, 0.15f) << out;
  EXPECT_LT(r.meanAlpha, 0.8f) << out;
  double lum = 0;
  for (const RGB& p : r.mean.pixels) lum += Luminance(p) / r.mean.pixels.size();
  EXPECT_GT(lum, 0.1) << out;
  EXPECT_LT(lum, 0.9) << out;

  if (std::getenv("MMRTM_UPDATE_BASELINES")) {
    WritePFM(baseline + ".pfm", r.mean);
    WritePFM(baseline + "_variance.pfm", r.variance);
    WritePNG(baseline + ".png", r.mean.width, r.mean.height, 3, r.png);
    GTEST_SKIP() << "baseline rewritten: look at " << baseline << ".png before committing it";
  }
  const RGBImage baseMean = ReadPFM(baseline + ".pfm"), baseVar = ReadPFM(baseline + "_variance.pfm");
  ASSERT_EQ(baseMean.width, r.mean.width);
  ASSERT_EQ(baseMean.height, r.mean.height);
  Comparison c = Compare(r, baseMean, baseVar);
  EXPECT_LT(c.meanZ2, 1.5) << "the image differs from the baseline beyond its noise; see " << out;
  EXPECT_LT(c.fractionOver4, 0.01) << "see " << out;
}

TEST(ImageCT, HeadBonePresetMatchesBaseline) { ExpectMatchesBaseline(RenderCranium(1), "ct_head_cranium_bone"); }

// The chest series through the DICOM loader, seen from the front (the preset's
// default camera, anterior in LPS): a wrong row order, slice order or
// orientation turns or mirrors the ribcage and fails the comparison.
TEST(ImageCT, ChestDicomSeriesMatchesBaseline) {
  ExpectMatchesBaseline(RenderBonePreset("ct_chest_dicom", nlohmann::json::object(), 1), "ct_chest_dicom_bone");
}

// The comparison is not vacuous: another seed passes, a 25% darker bone does not.
TEST(ImageCT, ComparisonSeparatesNoiseFromChange) {
  const RGBImage baseMean = ReadPFM(kBaseline + ".pfm"), baseVar = ReadPFM(kBaseline + "_variance.pfm");
  Comparison otherSeed = Compare(RenderCranium(99), baseMean, baseVar);
  EXPECT_LT(otherSeed.meanZ2, 1.5);
  EXPECT_GT(otherSeed.meanZ2, 0.5) << "independent noise should give z^2 near 1";
  Comparison darker = Compare(RenderCranium(99, 0.75f), baseMean, baseVar);
  std::printf("mean z^2: another seed %.3f, 25%% darker %.3f\n", otherSeed.meanZ2, darker.meanZ2);
  EXPECT_GT(darker.meanZ2, 1.5);
}

}  // namespace
}  // namespace mmrtm
