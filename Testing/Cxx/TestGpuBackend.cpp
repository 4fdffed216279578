// The CUDA backend against the CPU backend, on a GPU machine (`ctest -L gpu`;
// Documentation/gpu.md). Without a device every test is skipped with the
// reason. The integrator and the refit are the same source on both sides:
//   - the refit is integer-exact logic over the same summaries and tables,
//     so the GPU majorants equal the CPU ones bit for bit;
//   - the images of one seed take the same random numbers; they differ only
//     where device and host maths round differently (sinf, expf), which can
//     flip a rare Russian-roulette or collision decision, so nearly every
//     pixel agrees to float tolerance and the whole image agrees in z-score.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cpu_renderer.h"
#include "render_backend.h"
#include "cuda_device.h"
#include "gpu_renderer.h"
#include "mmrtmVolumeLoader.h"
#include "scene_json.h"

namespace mmrtm {
namespace {

#define SKIP_WITHOUT_DEVICE()                                    \
  if (!CudaDevice().available)                                   \
  GTEST_SKIP() << "no CUDA device here (" << CudaDevice().reason \
               << "); run `ctest -L gpu` on a GPU machine (Documentation/gpu.md)"

Scene HeadScene(uint64_t seed) {
  nlohmann::json doc = ReadJsonFile(std::string(MMRTM_DATA_DIR) + "/presets/ct-bone.json");
  doc["render"] = {{"width", 96}, {"height", 96}, {"spp", 16}, {"seed", seed}};
  SceneInputs inputs;
  inputs.volumes["scalars"] = LoadVolume(std::string(MMRTM_SHARED_DATA_DIR) + "/ct_head_cranium.nrrd");
  return SceneFromJson(doc, std::move(inputs));
}

// Pixels whose colours agree to float tolerance (device and host maths round
// differently).
int ClosePixels(const Film& a, const Film& b) {
  int close = 0;
  for (int y = 0; y < a.Height(); ++y)
    for (int x = 0; x < a.Width(); ++x) {
      const RGB p = a.Mean(x, y), q = b.Mean(x, y);
      bool ok = true;
      for (int c = 0; c < 3; ++c) ok = ok && std::fabs(p[c] - q[c]) <= 1e-4f + 1e-3f * std::fabs(p[c]);
      close += ok;
    }
  return close;
}

TEST(GpuBackend, RefitEqualsTheCpuRefitExactly) {
  SKIP_WITHOUT_DEVICE();
  Scene scene = HeadScene(1);
  const SceneView view = scene.Build();
  const MajorantGrid& grid = *scene.Grid();
  GpuRenderer gpu;
  gpu.SetScene(view);
  // Spoil nothing on the host: the device refit must reproduce the host's.
  gpu.Refit(grid, view.classifier, true);
  const std::vector<float> device = gpu.DownloadMajorants();
  ASSERT_EQ((int64_t)device.size(), grid.NodeCount());
  const float* host = grid.View().majorants;
  int64_t differ = 0, nonZero = 0;
  for (size_t i = 0; i < device.size(); ++i) {
    differ += device[i] != host[i];
    nonZero += host[i] > 0.f;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(nonZero, 0);
  // The minorant bytes alike (the same SummaryMinorant and UpperNodeBounds).
  const std::vector<uint8_t> deviceMinorants = gpu.DownloadMinorants();
  ASSERT_EQ((int64_t)deviceMinorants.size(), grid.NodeCount());
  const uint8_t* hostMinorants = grid.View().minorants;
  int64_t minorantsDiffer = 0;
  for (size_t i = 0; i < deviceMinorants.size(); ++i) minorantsDiffer += deviceMinorants[i] != hostMinorants[i];
  EXPECT_EQ(minorantsDiffer, 0);
}

TEST(GpuBackend, ImageMatchesTheCpuImageOfTheSameSeed) {
  SKIP_WITHOUT_DEVICE();
  Scene scene = HeadScene(7);
  const SceneView view = scene.Build();
  Film cpu(96, 96), gpu(96, 96);
  TraceCounters cpuCounters, gpuCounters;
  CpuRenderer(0).Render(view, cpu, 16, &cpuCounters);
  GpuRenderer renderer;
  renderer.SetScene(view);
  renderer.Render(gpu, 16, &gpuCounters);
  EXPECT_GE(ClosePixels(cpu, gpu), 96 * 96 * 99 / 100) << "pixels equal to float tolerance";
  EXPECT_LT(MeanSquaredZScore(cpu, gpu), 0.1);
  // The even samples' mean luminance comes back from the device too.
  EXPECT_NEAR(gpu.Noise().relative, cpu.Noise().relative, 0.02 * cpu.Noise().relative);
  EXPECT_GT(cpu.Noise().relative, 0.0);
  EXPECT_EQ(gpuCounters.paths, cpuCounters.paths);
  EXPECT_EQ(gpuCounters.majorantViolations, 0u);
}

TEST(GpuBackend, AccumulationContinuesOnTheDevice) {
  SKIP_WITHOUT_DEVICE();
  Scene scene = HeadScene(3);
  const SceneView view = scene.Build();
  GpuRenderer renderer;
  renderer.SetScene(view);
  Film twice(64, 64), once(64, 64);
  renderer.Render(twice, 4);
  renderer.Render(twice, 4);
  GpuRenderer other;
  other.SetScene(view);
  other.Render(once, 8);
  EXPECT_EQ(twice.Samples(), 8u);
  const RGBImage a = twice.Linear(), b = once.Linear();
  int differ = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) differ += a.pixels[i][c] != b.pixels[i][c];
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(twice.Noise().relative, once.Noise().relative);
}

// Adaptive sampling on the device: per-pixel counts give the CPU's image
// (the same sample indices per pixel), and the per-pixel work comes back.
TEST(GpuBackend, PerPixelCountsMatchTheCpu) {
  SKIP_WITHOUT_DEVICE();
  Scene scene = HeadScene(5);
  const SceneView view = scene.Build();
  std::vector<uint32_t> counts(64 * 64);
  for (size_t i = 0; i < counts.size(); ++i) counts[i] = 4 + (uint32_t)(i * 7 % 13);
  Film cpu(64, 64), gpu(64, 64);
  cpu.TrackWork();
  gpu.TrackWork();
  TraceCounters cpuCounters, gpuCounters;
  CpuRenderer(0).Render(view, cpu, 4, &cpuCounters);
  CpuRenderer(0).RenderTo(view, cpu, counts, &cpuCounters);
  GpuRenderer renderer;
  renderer.SetScene(view);
  renderer.Render(gpu, 4, &gpuCounters);
  renderer.RenderTo(gpu, counts, &gpuCounters);
  ASSERT_TRUE(gpu.Adaptive());
  EXPECT_EQ(gpu.PixelSamples(10, 20), counts[20 * 64 + 10]);
  EXPECT_EQ(gpuCounters.paths, cpuCounters.paths);
  double workCpu = 0, workGpu = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      workCpu += cpu.Work(x, y);
      workGpu += gpu.Work(x, y);
    }
  EXPECT_GE(ClosePixels(cpu, gpu), 64 * 64 * 99 / 100) << "pixels equal to float tolerance";
  EXPECT_NEAR(gpu.Noise().relative, cpu.Noise().relative, 0.02 * cpu.Noise().relative);
  EXPECT_GT(workCpu, 0.0);
  EXPECT_NEAR(workGpu, workCpu, 0.01 * workCpu);
}

// The CUDA backend uploads only what an edit changed (SceneUploadPlanner;
// TestSceneUploads counts its requests without a device). Here, on the
// device: after each edit, the backend that kept its device copies renders
// the same image, to the bit, as a new backend that uploads everything. A
// part kept that should have gone up (stale tables, voxels or majorants)
// changes the image.
TEST(GpuBackend, AfterEachEditTheKeptDeviceSceneRendersAsAFreshUpload) {
  SKIP_WITHOUT_DEVICE();
  Scene scene = HeadScene(9);
  std::unique_ptr<Renderer> kept = MakeRenderer(Backend::Cuda, 0);
  auto render = [&](Renderer& renderer, const SceneView& view) {
    Film film(64, 64);
    renderer.Render(scene, view, film, 4, nullptr, nullptr);
    return film.Linear();
  };
  render(*kept, scene.Build());
  // The preset's TFs by what they are bound to (their order is the JSON's).
  auto boundTo = [&](Quantity q) -> TransferFunctionDesc& {
    for (const MaterialDesc::Binding& b : scene.materials[0].bindings)
      if (b.quantity == q) return scene.tfs[(size_t)b.tf];
    throw std::runtime_error("ct-bone has no TF for that quantity");
  };
  const std::vector<std::pair<std::string, std::function<void()>>> edits = {
      {"camera", [&] { scene.camera.azimuth += 40.f; }},
      {"albedo TF", [&] { boundTo(Quantity::Albedo).values[0] = 0.2f; }},
      {"density TF", [&] { boundTo(Quantity::Density).values[1] = 0.9f; }},
      {"material colour", [&] { scene.materials[0].base[1] = 0.3f; }},
      {"voxels edited in place",
       [&] {
         HostVolume& v = scene.proxies[0];
         auto* voxels = reinterpret_cast<int16_t*>(v.voxels.MutableData());
         ASSERT_EQ(v.type, VoxelType::Int16);
         for (size_t i = 0; i < v.voxels.size() / 2; i += 3) voxels[i] = 1500;
         scene.MarkDataModified();
       }},
      {"cropping (no minorants)",
       [&] {
         scene.cropping.keep = 0x2ebfeba;  // VTK's fence
         const auto b = scene.proxies[0].WorldBounds();
         for (int a = 0; a < 3; ++a) {
           scene.cropping.lo[a] = 0.6f * (&b[0].x)[a] + 0.4f * (&b[1].x)[a];
           scene.cropping.hi[a] = 0.4f * (&b[0].x)[a] + 0.6f * (&b[1].x)[a];
         }
       }},
      {"cropping off", [&] { scene.cropping.keep = Classifier::kNoCropping; }},
      {"nothing", [] {}},
  };
  for (const auto& [name, edit] : edits) {
    SCOPED_TRACE(name);
    edit();
    const SceneView view = scene.Build();
    const RGBImage a = render(*kept, view);
    std::unique_ptr<Renderer> fresh = MakeRenderer(Backend::Cuda, 0);
    const RGBImage b = render(*fresh, view);
    int differ = 0;
    double sum = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        differ += a.pixels[i][c] != b.pixels[i][c];
        sum += b.pixels[i][c];
      }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(sum, 0.0) << "a black image proves nothing";
  }
}

}  // namespace
}  // namespace mmrtm
