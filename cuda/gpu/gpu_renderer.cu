// The CUDA-only part of the backend: device memory, the launches and the
// refit kernels. Everything traced per sample is the shared code in
// cuda/include/mmrtm, proven on the CPU.
#include "gpu_renderer.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>

#include "cuda_device.h"
#include "device_buffer.h"
#include "mmrtm/integrator.h"
#include "mmrtm/majorant_refit.h"
#include "mmrtm/projection.h"
#include "scene_relocation.h"

namespace mmrtm {
namespace {

constexpr int kBlockX = 16, kBlockY = 8;

// Sample `index` of every pixel, or with per-pixel ranges (adaptive
// sampling) of the pixels whose range [first, end) holds it; the counters
// are summed per thread, then added once.
__global__ void RenderSampleKernel(SceneView scene, FilmView film, uint32_t index, const uint32_t* first,
                                   const uint32_t* end, TraceCounters* counters) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= film.width || y >= film.height) return;
  const int64_t pixel = x + (int64_t)film.width * y;
  if (first && (index < first[pixel] || index >= end[pixel])) return;
  TraceCounters ctr;
  const PixelSample ps = scene.settings.projection.mode != IntensityProjection::None
                             ? ProjectPixel(scene, x, y, ctr)
                             : RenderPixelSample(scene, x, y, index, ctr);
  film.AddSample(x, y, ps.L, ps.alpha, index + 1);
  film.AddDenoiserInputs(x, y, ps.L, ps.albedo, ps.normal, index + 1);
  film.AddWork(x, y, (float)ctr.Work());
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

__global__ void RefitSummariesKernel(Classifier c, RefitInputs in, float* bounds, uint8_t* lowerBounds,
                                     int64_t summaries) {
  const int64_t s = (int64_t)blockIdx.x * blockDim.x + threadIdx.x;
  if (s >= summaries) return;
  bounds[s] = SummaryMajorant(c, in, s);
  lowerBounds[s] = EncodeMinorant(bounds[s], SummaryMinorant(c, in, s));
}

__global__ void RefitLeavesKernel(const float* bounds, const uint8_t* lowerBounds, const uint32_t* leafSummaryIds,
                                  float* majorants, uint8_t* minorants, int64_t leafOffset, int64_t leaves) {
  const int64_t leaf = (int64_t)blockIdx.x * blockDim.x + threadIdx.x;
  if (leaf >= leaves) return;
  majorants[leafOffset + leaf] = bounds[leafSummaryIds[leaf]];
  minorants[leafOffset + leaf] = lowerBounds[leafSummaryIds[leaf]];
}

__global__ void RefitLevelKernel(MajorantGridView g, float* majorants, uint8_t* minorants, int level) {
  const int64_t i = (int64_t)blockIdx.x * blockDim.x + threadIdx.x;
  const int* r = g.res[level];
  if (i >= (int64_t)r[0] * r[1] * r[2]) return;
  const int x = (int)(i % r[0]), y = (int)((i / r[0]) % r[1]), z = (int)(i / ((int64_t)r[0] * r[1]));
  UpperNodeBounds(g, majorants, minorants, level, x, y, z);
}

int Blocks(int64_t n, int threads) { return (int)((n + threads - 1) / threads); }

}  // namespace

struct GpuRenderer::Impl {
  SceneView device;  // the uploaded scene
  bool hasScene = false;
  // Voxels by (host address, bytes): kept across SetScene until uploads.voxels.
  std::map<std::pair<const void*, size_t>, DeviceBuffer> voxels;
  // Everything else, by part (tables, grid, environment), in the order
  // RelocateSceneView visits it: a part not uploaded keeps its buffers.
  enum Part { kTables, kGrid, kEnvironment, kParts };
  std::vector<DeviceBuffer> parts[kParts];
  float* majorants = nullptr;    // inside parts[kGrid]
  uint8_t* minorants = nullptr;  // inside parts[kGrid], as many
  size_t majorantCount = 0;
  DeviceBuffer summaries[kMaxProxies], leafSummaryIds, summaryBounds, summaryLowerBounds, binMax, binMaterials, binMin,
      uncoveredBins;
  DeviceBuffer filmMean, filmM2, filmEven, filmWork, filmDenoiserInputs, counters, rangeFirst, rangeEnd;
  int filmWidth = 0, filmHeight = 0;
  uint32_t filmSamples = 0;
  bool filmUniform = true;  // false after RenderTo: the next Render uploads the film
  bool hasWork = false;     // the device film has per-pixel work (Film::TrackWork)
  bool hasDenoiserInputs = false;  // and the denoiser's inputs (Film::TrackDenoiserInputs)

  // Puts the host film on the device (mean, M2, the even samples' mean
  // luminance, and work and the denoiser's inputs when tracked).
  void UploadFilm(const FilmView& host) {
    const size_t pixels = (size_t)host.width * host.height;
    filmMean.Allocate(pixels * 4 * sizeof(float), "the film");
    filmM2.Allocate(pixels * 3 * sizeof(float), "the film");
    filmEven.Allocate(pixels * sizeof(float), "the film");
    filmMean.Upload(host.mean, pixels * 4 * sizeof(float));
    filmM2.Upload(host.m2, pixels * 3 * sizeof(float));
    filmEven.Upload(host.evenLuminance, pixels * sizeof(float));
    filmWork = DeviceBuffer();
    if (host.work) {
      filmWork.Allocate(pixels * sizeof(float), "the film");
      filmWork.Upload(host.work, pixels * sizeof(float));
    }
    hasWork = host.work != nullptr;
    const size_t inputs = pixels * FilmView::kDenoiserInputFloats * sizeof(float);
    filmDenoiserInputs = DeviceBuffer();
    if (host.denoiserInputs) {
      filmDenoiserInputs.Allocate(inputs, "the film");
      filmDenoiserInputs.Upload(host.denoiserInputs, inputs);
    }
    hasDenoiserInputs = host.denoiserInputs != nullptr;
    filmWidth = host.width;
    filmHeight = host.height;
  }
  FilmView DeviceFilm() {
    return FilmView{filmWidth,
                    filmHeight,
                    filmMean.As<float>(),
                    filmM2.As<float>(),
                    hasWork ? filmWork.As<float>() : nullptr,
                    filmEven.As<float>(),
                    hasDenoiserInputs ? filmDenoiserInputs.As<float>() : nullptr};
  }
  void DownloadFilm(const FilmView& host) const {
    const size_t pixels = (size_t)host.width * host.height;
    filmMean.Download(host.mean, pixels * 4 * sizeof(float));
    filmM2.Download(host.m2, pixels * 3 * sizeof(float));
    filmEven.Download(host.evenLuminance, pixels * sizeof(float));
    if (host.work) filmWork.Download(host.work, pixels * sizeof(float));
    if (host.denoiserInputs)
      filmDenoiserInputs.Download(host.denoiserInputs, pixels * FilmView::kDenoiserInputFloats * sizeof(float));
  }

  // Renders sample indices [from, to) of every pixel, or with per-pixel
  // ranges [first, end) of the pixels whose range holds them; one launch
  // per index: short kernels (no display watchdog), progress. Returns the
  // pass's counters through `out` (when given).
  void LaunchSamples(uint32_t from, uint32_t to, const uint32_t* first, const uint32_t* end,
                     const GpuRenderer::Progress& progress, TraceCounters* out) {
    SceneView scene = device;
    scene.camera.width = filmWidth;
    scene.camera.height = filmHeight;
    scene.settings.firstHitGuides = hasDenoiserInputs;
    const FilmView film = DeviceFilm();
    MMRTM_CUDA_CHECK(cudaMemset(counters.Get(), 0, sizeof(TraceCounters)));
    const dim3 block(kBlockX, kBlockY), grid((filmWidth + kBlockX - 1) / kBlockX, (filmHeight + kBlockY - 1) / kBlockY);
    for (uint32_t index = from; index < to; ++index) {
      RenderSampleKernel<<<grid, block>>>(scene, film, index, first, end, counters.As<TraceCounters>());
      MMRTM_CUDA_CHECK(cudaGetLastError());
      if (progress) {
        MMRTM_CUDA_CHECK(cudaDeviceSynchronize());
        progress((int)(index - from + 1), (int)(to - from));
      }
    }
    MMRTM_CUDA_CHECK(cudaDeviceSynchronize());
    if (out) {
      TraceCounters c;
      counters.Download(&c, sizeof c);
      *out += c;
    }
  }
};

GpuRenderer::GpuRenderer() : impl_(new Impl) {
  const CudaDeviceStatus& status = CudaDevice();
  if (!status.available) throw CudaError("the CUDA backend needs a CUDA device: " + status.reason);
  MMRTM_CUDA_CHECK(cudaSetDevice(0));
  impl_->counters.Allocate(sizeof(TraceCounters), "counters");
}

GpuRenderer::~GpuRenderer() = default;

void GpuRenderer::SetScene(const SceneView& view, const SceneUploads& uploads) {
  Impl& m = *impl_;
  if (uploads.voxels) m.voxels.clear();
  const bool upload[Impl::kParts] = {uploads.tables || !m.hasScene, uploads.majorants || !m.hasScene,
                                     uploads.environment || !m.hasScene};
  // Memory check before any allocation: what is not already on the device.
  const SceneFootprint footprint = MeasureSceneView(view);
  size_t kept = 0;
  for (int i = 0; i < view.classifier.proxyCount; ++i) {
    const VolumeView& v = view.classifier.proxies[i];
    auto it = m.voxels.find({v.data, (size_t)v.nx * v.ny * v.nz * VoxelTypeSize(v.type)});
    if (it != m.voxels.end()) kept += it->second.Bytes();
  }
  if (!upload[Impl::kTables]) kept += footprint.tables;
  if (!upload[Impl::kGrid]) kept += footprint.majorants + footprint.minorants;
  if (!upload[Impl::kEnvironment]) kept += footprint.environment;
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

  std::vector<DeviceBuffer> parts[Impl::kParts];
  std::map<std::pair<const void*, size_t>, DeviceBuffer> voxels;
  float* majorants = nullptr;
  uint8_t* minorants = nullptr;
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
    const bool grid = kind == SceneArrayKind::Majorants || kind == SceneArrayKind::Minorants;
    const int part = grid ? Impl::kGrid : kind == SceneArrayKind::Environment ? Impl::kEnvironment : Impl::kTables;
    std::vector<DeviceBuffer>& previous = m.parts[part];
    const size_t index = parts[part].size();
    if (!upload[part] && index < previous.size() && previous[index].Bytes() == bytes) {
      parts[part].push_back(std::move(previous[index]));
    } else {
      parts[part].emplace_back(bytes, grid ? "majorants" : part == Impl::kEnvironment ? "environment" : "scene tables");
      parts[part].back().Upload(host, bytes);
    }
    if (kind == SceneArrayKind::Majorants) majorants = parts[part].back().As<float>();
    if (kind == SceneArrayKind::Minorants) minorants = parts[part].back().As<uint8_t>();
    return parts[part].back().Get();
  });
  m.voxels = std::move(voxels);
  for (int part = 0; part < Impl::kParts; ++part) m.parts[part] = std::move(parts[part]);
  m.majorants = majorants;
  m.minorants = minorants;
  m.majorantCount = footprint.majorants / sizeof(float);
  m.hasScene = true;
}

void GpuRenderer::Refit(const MajorantGrid& grid, const Classifier& classifier, bool summariesChanged) {
  Impl& m = *impl_;
  if (!m.hasScene || !m.majorants || !m.minorants)
    throw CudaError("GpuRenderer::Refit: the uploaded scene has no majorant grid");
  if ((size_t)grid.NodeCount() != m.majorantCount)
    throw CudaError("GpuRenderer::Refit: the grid does not match the uploaded scene");
  RefitInputs in;
  const int64_t leaves = grid.LeafCount();
  const std::vector<uint32_t>& ids = grid.LeafSummaryIds();
  const LeafSummaryTable& table = grid.Summaries();
  if (ids.size() != (size_t)leaves)
    throw CudaError("GpuRenderer::Refit: the grid has no per-leaf summaries (voxel-value refit?)");
  const bool upload = summariesChanged || m.leafSummaryIds.Bytes() != ids.size() * sizeof(uint32_t) ||
                      m.summaryBounds.Bytes() != table.Count() * sizeof(float);
  if (upload) {
    m.leafSummaryIds.Allocate(ids.size() * sizeof(uint32_t), "majorant summaries");
    m.leafSummaryIds.Upload(ids.data(), ids.size() * sizeof(uint32_t));
    m.summaryBounds.Allocate(table.Count() * sizeof(float), "majorant summaries");
    m.summaryLowerBounds.Allocate(table.Count() * sizeof(uint8_t), "majorant summaries");
  }
  for (int k = 0; k < grid.ProxyCount(); ++k) {
    const std::vector<uint64_t>& s = table.WordVector(k);
    if (upload) {
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
  m.binMin.Allocate(t.binMin.size() * sizeof(float), "refit tables");
  m.binMin.Upload(t.binMin.data(), t.binMin.size() * sizeof(float));
  m.uncoveredBins.Allocate(t.uncoveredBins.size() * sizeof(uint64_t), "refit tables");
  m.uncoveredBins.Upload(t.uncoveredBins.data(), t.uncoveredBins.size() * sizeof(uint64_t));
  in.binMax = m.binMax.As<float>();
  in.binMaterials = m.binMaterials.As<uint64_t>();
  in.binMin = m.binMin.As<float>();
  in.uncoveredBins = m.uncoveredBins.As<uint64_t>();
  in.materialMasks = t.materialMasks;

  const MajorantGridView& g = m.device.majorants.grid;
  constexpr int kThreads = 256;
  const int64_t summaries = (int64_t)table.Count();
  if (summaries > 0) {
    RefitSummariesKernel<<<Blocks(summaries, kThreads), kThreads>>>(
        m.device.classifier, in, m.summaryBounds.As<float>(), m.summaryLowerBounds.As<uint8_t>(), summaries);
    MMRTM_CUDA_CHECK(cudaGetLastError());
  }
  RefitLeavesKernel<<<Blocks(leaves, kThreads), kThreads>>>(
      m.summaryBounds.As<float>(), m.summaryLowerBounds.As<uint8_t>(), m.leafSummaryIds.As<uint32_t>(), m.majorants,
      m.minorants, g.offset[g.leafLevel], leaves);
  MMRTM_CUDA_CHECK(cudaGetLastError());
  for (int level = g.leafLevel - 1; level >= 0; --level) {
    const int64_t nodes = (int64_t)g.res[level][0] * g.res[level][1] * g.res[level][2];
    RefitLevelKernel<<<Blocks(nodes, kThreads), kThreads>>>(g, m.majorants, m.minorants, level);
    MMRTM_CUDA_CHECK(cudaGetLastError());
  }
  MMRTM_CUDA_CHECK(cudaDeviceSynchronize());
}

std::vector<uint8_t> GpuRenderer::DownloadMinorants() const {
  std::vector<uint8_t> out(impl_->minorants ? impl_->majorantCount : 0);
  if (!out.empty()) MMRTM_CUDA_CHECK(cudaMemcpy(out.data(), impl_->minorants, out.size(), cudaMemcpyDeviceToHost));
  return out;
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
  const FilmView host = film.View();
  // The device accumulation continues the host film's: after a reset or a
  // resize (or the first time) the host's state goes up.
  if (film.Adaptive()) throw CudaError("GpuRenderer::Render: the film has per-pixel counts (use RenderTo)");
  if (width != m.filmWidth || height != m.filmHeight || film.Samples() != m.filmSamples || !m.filmUniform ||
      (host.work != nullptr) != m.hasWork || (host.denoiserInputs != nullptr) != m.hasDenoiserInputs) {
    m.UploadFilm(host);
    m.filmSamples = film.Samples();
    m.filmUniform = true;
  }
  m.LaunchSamples(m.filmSamples, m.filmSamples + (uint32_t)samplesPerPixel, nullptr, nullptr, progress, counters);
  m.filmSamples += (uint32_t)samplesPerPixel;
  m.DownloadFilm(host);
  film.AddSamples((uint32_t)samplesPerPixel);
}

void GpuRenderer::RenderTo(Film& film, const std::vector<uint32_t>& targetCounts, TraceCounters* counters,
                           const Progress& progress) {
  Impl& m = *impl_;
  if (!m.hasScene) throw CudaError("GpuRenderer::RenderTo: no scene uploaded (SetScene)");
  const int width = film.Width(), height = film.Height();
  const size_t pixels = (size_t)width * height;
  if (targetCounts.size() != pixels) throw CudaError("GpuRenderer::RenderTo: one sample count per pixel expected");
  std::vector<uint32_t> first(pixels), end(pixels);
  uint32_t lowest = UINT32_MAX, highest = 0;
  for (size_t i = 0; i < pixels; ++i) {
    first[i] = film.PixelSamples((int)(i % width), (int)(i / width));
    end[i] = std::max(first[i], targetCounts[i]);
    if (end[i] > first[i]) {
      lowest = std::min(lowest, first[i]);
      highest = std::max(highest, end[i]);
    }
  }
  // Per-pixel counts: the host film goes up every time (a few MB, once a pass).
  const FilmView host = film.View();
  m.UploadFilm(host);
  m.filmUniform = false;
  m.rangeFirst.Allocate(pixels * sizeof(uint32_t), "sample counts");
  m.rangeEnd.Allocate(pixels * sizeof(uint32_t), "sample counts");
  m.rangeFirst.Upload(first.data(), pixels * sizeof(uint32_t));
  m.rangeEnd.Upload(end.data(), pixels * sizeof(uint32_t));
  if (lowest < highest)
    m.LaunchSamples(lowest, highest, m.rangeFirst.As<uint32_t>(), m.rangeEnd.As<uint32_t>(), progress, counters);
  m.DownloadFilm(host);
  film.SetPixelSamples(std::move(end));
}

}  // namespace mmrtm
