// The CUDA-only part of the backend: device memory, the launches and the
// refit kernels. Everything traced per sample is the shared code in
// cuda/include/mmrtm, proven on the CPU.
#include "gpu_renderer.h"

#include <map>
#include <utility>

#include "cuda_device.h"
#include "device_buffer.h"
#include "mmrtm/integrator.h"
#include "mmrtm/majorant_refit.h"
#include "scene_relocation.h"

namespace mmrtm {
namespace {

constexpr int kBlockX = 16, kBlockY = 8;

// One sample of every pixel; the counters are summed per thread, then added
// once.
__global__ void RenderSampleKernel(SceneView scene, FilmView film, uint32_t index, TraceCounters* counters) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= film.width || y >= film.height) return;
  TraceCounters ctr;
  const PixelSample ps = RenderPixelSample(scene, x, y, index, ctr);
  film.AddSample(x, y, ps.L, ps.alpha, index + 1);
  auto add = [](uint64_t* total, uint64_t v) {
    if (v) atomicAdd(reinterpret_cast<unsigned long long*>(total), (unsigned long long)v);
  };
  add(&counters->paths, ctr.paths);
  add(&counters->densityLookups, ctr.densityLookups);
  add(&counters->realCollisions, ctr.realCollisions);
  add(&counters->nullCollisions, ctr.nullCollisions);
  add(&counters->shadowRays, ctr.shadowRays);
  add(&counters->majorantSegments, ctr.majorantSegments);
  add(&counters->majorantViolations, ctr.majorantViolations);
}

__global__ void RefitLeavesKernel(Classifier c, RefitInputs in, float* majorants, int64_t leafOffset, int64_t leaves) {
  const int64_t leaf = (int64_t)blockIdx.x * blockDim.x + threadIdx.x;
  if (leaf < leaves) majorants[leafOffset + leaf] = LeafMajorant(c, in, leaf);
}

__global__ void RefitLevelKernel(MajorantGridView g, float* majorants, int level) {
  const int64_t i = (int64_t)blockIdx.x * blockDim.x + threadIdx.x;
  const int* r = g.res[level];
  if (i >= (int64_t)r[0] * r[1] * r[2]) return;
  const int x = (int)(i % r[0]), y = (int)((i / r[0]) % r[1]), z = (int)(i / ((int64_t)r[0] * r[1]));
  majorants[g.Index(level, x, y, z)] = UpperNodeMajorant(g, majorants, level, x, y, z);
}

int Blocks(int64_t n, int threads) { return (int)((n + threads - 1) / threads); }

}  // namespace

struct GpuRenderer::Impl {
  SceneView device;  // the uploaded scene
  bool hasScene = false;
  // Voxels by (host address, bytes): kept across SetScene without dataChanged.
  std::map<std::pair<const void*, size_t>, DeviceBuffer> voxels;
  std::vector<DeviceBuffer> tables;  // everything else, replaced on every SetScene
  float* majorants = nullptr;        // inside `tables`
  size_t majorantCount = 0;
  DeviceBuffer summaries[kMaxProxies], binMax, binMaterials;
  DeviceBuffer filmMean, filmM2, counters;
  int filmWidth = 0, filmHeight = 0;
  uint32_t filmSamples = 0;
};

GpuRenderer::GpuRenderer() : impl_(new Impl) {
  const CudaDeviceStatus& status = CudaDevice();
  if (!status.available) throw CudaError("the CUDA backend needs a CUDA device: " + status.reason);
  MMRTM_CUDA_CHECK(cudaSetDevice(0));
  impl_->counters.Allocate(sizeof(TraceCounters), "counters");
}

GpuRenderer::~GpuRenderer() = default;

void GpuRenderer::SetScene(const SceneView& view, bool dataChanged) {
  Impl& m = *impl_;
  if (dataChanged) m.voxels.clear();
  // Memory check before any allocation: what is not already on the device.
  const SceneFootprint footprint = MeasureSceneView(view);
  size_t kept = 0;
  for (int i = 0; i < view.classifier.proxyCount; ++i) {
    const VolumeView& v = view.classifier.proxies[i];
    auto it = m.voxels.find({v.data, (size_t)v.nx * v.ny * v.nz * VoxelTypeSize(v.type)});
    if (it != m.voxels.end()) kept += it->second.Bytes();
  }
  size_t freeBytes = 0, totalBytes = 0;
  MMRTM_CUDA_CHECK(cudaMemGetInfo(&freeBytes, &totalBytes));
  const size_t needed = footprint.Total() - kept;
  if (needed > freeBytes)
    throw DeviceMemoryError("not enough GPU memory for the scene: " + DeviceBuffer::Megabytes(needed) + " needed (" +
                            DeviceBuffer::Megabytes(footprint.voxels) + " voxels, " +
                            DeviceBuffer::Megabytes(footprint.majorants) + " majorants, " +
                            DeviceBuffer::Megabytes(footprint.tables + footprint.environment) +
                            " tables and environment), " + DeviceBuffer::Megabytes(freeBytes) + " free of " +
                            DeviceBuffer::Megabytes(totalBytes));

  std::vector<DeviceBuffer> tables;
  std::map<std::pair<const void*, size_t>, DeviceBuffer> voxels;
  float* majorants = nullptr;
  m.device = RelocateSceneView(view, [&](const void* host, size_t bytes, SceneArrayKind kind) -> const void* {
    if (kind == SceneArrayKind::Voxels) {
      const auto key = std::make_pair(host, bytes);
      auto it = m.voxels.find(key);
      if (it != m.voxels.end()) return (voxels[key] = std::move(it->second)).Get();
      DeviceBuffer& b = voxels[key];
      b.Allocate(bytes, "voxels");
      b.Upload(host, bytes);
      return b.Get();
    }
    tables.emplace_back(bytes, kind == SceneArrayKind::Majorants ? "majorants" : "scene tables");
    tables.back().Upload(host, bytes);
    if (kind == SceneArrayKind::Majorants) majorants = tables.back().As<float>();
    return tables.back().Get();
  });
  m.voxels = std::move(voxels);
  m.tables = std::move(tables);
  m.majorants = majorants;
  m.majorantCount = footprint.majorants / sizeof(float);
  m.hasScene = true;
}

void GpuRenderer::Refit(const MajorantGrid& grid, const Classifier& classifier, bool summariesChanged) {
  Impl& m = *impl_;
  if (!m.hasScene || !m.majorants) throw CudaError("GpuRenderer::Refit: the uploaded scene has no majorant grid");
  if ((size_t)grid.NodeCount() != m.majorantCount)
    throw CudaError("GpuRenderer::Refit: the grid does not match the uploaded scene");
  RefitInputs in;
  const int64_t leaves = grid.LeafCount();
  for (int k = 0; k < grid.ProxyCount(); ++k) {
    const std::vector<uint64_t>& s = grid.Summaries(k);
    if (s.size() != (size_t)leaves * kSummaryWords)
      throw CudaError("GpuRenderer::Refit: the grid has no per-leaf summaries (voxel-value refit?)");
    if (summariesChanged || m.summaries[k].Bytes() != s.size() * sizeof(uint64_t)) {
      m.summaries[k].Allocate(s.size() * sizeof(uint64_t), "majorant summaries");
      m.summaries[k].Upload(s.data(), s.size() * sizeof(uint64_t));
    }
    in.summaries[k] = m.summaries[k].As<uint64_t>();
  }
  const MajorantGrid::RefitTables t = grid.MakeRefitTables(classifier);
  m.binMax.Allocate(t.binMax.size() * sizeof(float), "refit tables");
  m.binMax.Upload(t.binMax.data(), t.binMax.size() * sizeof(float));
  m.binMaterials.Allocate(t.binMaterials.size() * sizeof(uint64_t), "refit tables");
  m.binMaterials.Upload(t.binMaterials.data(), t.binMaterials.size() * sizeof(uint64_t));
  in.binMax = m.binMax.As<float>();
  in.binMaterials = m.binMaterials.As<uint64_t>();
  in.materialMasks = t.materialMasks;

  const MajorantGridView& g = m.device.majorants.grid;
  constexpr int kThreads = 256;
  RefitLeavesKernel<<<Blocks(leaves, kThreads), kThreads>>>(m.device.classifier, in, m.majorants,
                                                            g.offset[g.leafLevel], leaves);
  MMRTM_CUDA_CHECK(cudaGetLastError());
  for (int level = g.leafLevel - 1; level >= 0; --level) {
    const int64_t nodes = (int64_t)g.res[level][0] * g.res[level][1] * g.res[level][2];
    RefitLevelKernel<<<Blocks(nodes, kThreads), kThreads>>>(g, m.majorants, level);
    MMRTM_CUDA_CHECK(cudaGetLastError());
  }
  MMRTM_CUDA_CHECK(cudaDeviceSynchronize());
}

std::vector<float> GpuRenderer::DownloadMajorants() const {
  std::vector<float> out(impl_->majorantCount);
  if (!out.empty())
    MMRTM_CUDA_CHECK(cudaMemcpy(out.data(), impl_->majorants, out.size() * sizeof(float), cudaMemcpyDeviceToHost));
  return out;
}

void GpuRenderer::Render(Film& film, int samplesPerPixel, TraceCounters* counters, const Progress& progress) {
  Impl& m = *impl_;
  if (!m.hasScene) throw CudaError("GpuRenderer::Render: no scene uploaded (SetScene)");
  const int width = film.Width(), height = film.Height();
  const size_t pixels = (size_t)width * height;
  FilmView host = film.View();
  // The device accumulation continues the host film's: after a reset or a
  // resize (or the first time) the host's state goes up.
  if (width != m.filmWidth || height != m.filmHeight || film.Samples() != m.filmSamples) {
    m.filmMean.Allocate(pixels * 4 * sizeof(float), "the film");
    m.filmM2.Allocate(pixels * 3 * sizeof(float), "the film");
    m.filmMean.Upload(host.mean, pixels * 4 * sizeof(float));
    m.filmM2.Upload(host.m2, pixels * 3 * sizeof(float));
    m.filmWidth = width;
    m.filmHeight = height;
    m.filmSamples = film.Samples();
  }
  FilmView device{width, height, m.filmMean.As<float>(), m.filmM2.As<float>()};
  SceneView scene = m.device;
  scene.camera.width = width;
  scene.camera.height = height;
  MMRTM_CUDA_CHECK(cudaMemset(m.counters.Get(), 0, sizeof(TraceCounters)));

  const dim3 block(kBlockX, kBlockY), grid((width + kBlockX - 1) / kBlockX, (height + kBlockY - 1) / kBlockY);
  for (int i = 0; i < samplesPerPixel; ++i) {
    // One launch per sample: short kernels (no display watchdog), progress.
    RenderSampleKernel<<<grid, block>>>(scene, device, m.filmSamples + (uint32_t)i, m.counters.As<TraceCounters>());
    MMRTM_CUDA_CHECK(cudaGetLastError());
    if (progress) {
      MMRTM_CUDA_CHECK(cudaDeviceSynchronize());
      progress(i + 1, samplesPerPixel);
    }
  }
  MMRTM_CUDA_CHECK(cudaDeviceSynchronize());
  m.filmSamples += (uint32_t)samplesPerPixel;

  m.filmMean.Download(host.mean, pixels * 4 * sizeof(float));
  m.filmM2.Download(host.m2, pixels * 3 * sizeof(float));
  film.AddSamples((uint32_t)samplesPerPixel);
  if (counters) {
    TraceCounters c;
    m.counters.Download(&c, sizeof c);
    *counters += c;
  }
}

}  // namespace mmrtm
