#include "cpu_renderer.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "mmrtm/integrator.h"
#include "cpu_projection.h"

namespace mmrtm {

CpuRenderer::CpuRenderer(int threads)
    : threads_(threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency())) {}

std::string CpuRenderer::Description() const { return "cpu, " + std::to_string(threads_) + " thread(s)"; }

bool CpuRenderer::Render(const SceneView& scene, Film& film, int samplesPerPixel, TraceCounters* counters,
                         const Progress& progress, const std::atomic<bool>* cancel) const {
  const auto end = [&](size_t, uint32_t first) { return first + (uint32_t)samplesPerPixel; };
  if (!RenderRanges(scene, film, end, counters, progress, cancel)) return false;
  film.AddSamples((uint32_t)samplesPerPixel);
  return true;
}

bool CpuRenderer::RenderTo(const SceneView& scene, Film& film, const std::vector<uint32_t>& targetCounts,
                           TraceCounters* counters, const Progress& progress, const std::atomic<bool>* cancel) const {
  const size_t pixels = (size_t)film.Width() * film.Height();
  if (targetCounts.size() != pixels)
    throw std::invalid_argument("CpuRenderer::RenderTo: " + std::to_string(targetCounts.size()) +
                                " sample counts for " + std::to_string(pixels) + " pixels");
  // Each pixel ends with its target, or its own count where that is more.
  std::vector<uint32_t> counts(pixels);
  for (size_t i = 0; i < pixels; ++i)
    counts[i] = std::max(film.PixelSamples((int)(i % film.Width()), (int)(i / film.Width())), targetCounts[i]);
  if (!RenderRanges(
          scene, film, [&](size_t pixel, uint32_t) { return counts[pixel]; }, counters, progress, cancel))
    return false;
  film.SetPixelSamples(std::move(counts));
  return true;
}

bool CpuRenderer::RenderRanges(const SceneView& scene, Film& film, const std::function<uint32_t(size_t, uint32_t)>& end,
                               TraceCounters* counters, const Progress& progress,
                               const std::atomic<bool>* cancel) const {
  const int width = film.Width(), height = film.Height();
  const int tilesX = (width + kTileSize - 1) / kTileSize, tilesY = (height + kTileSize - 1) / kTileSize;
  const int tileCount = tilesX * tilesY;
  FilmView view = film.View();
  SceneView s = scene;
  s.camera.width = width;
  s.camera.height = height;
  s.settings.firstHitGuides = view.denoiserInputs != nullptr;

  std::atomic<int> nextTile{0};
  std::mutex progressMutex;
  int tilesDone = 0;
  std::vector<TraceCounters> perThread(threads_);

  const bool projecting = s.settings.projection.mode != IntensityProjection::None;  // mmrtm/projection.h
  auto worker = [&](int thread) {
    TraceCounters& ctr = perThread[thread];
    for (int tile; (tile = nextTile.fetch_add(1)) < tileCount;) {
      if (cancel && cancel->load(std::memory_order_relaxed)) break;
      const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
      const int x1 = std::min(x0 + kTileSize, width), y1 = std::min(y0 + kTileSize, height);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const uint32_t first = film.PixelSamples(x, y), last = end((size_t)y * width + x, first);
          if (projecting) {
            for (uint32_t index = first; index < last; ++index) {
              const PixelSample ps = ProjectPixelOnCpu(s, x, y, ctr);
              view.AddSample(x, y, ps.L, ps.alpha, index + 1);
            }
            continue;
          }
          const uint64_t workBefore = ctr.Work();
          for (uint32_t index = first; index < last; ++index) {
            PixelSample ps = RenderPixelSample(s, x, y, index, ctr);
            view.AddSample(x, y, ps.L, ps.alpha, index + 1);
            view.AddDenoiserInputs(x, y, ps.L, ps.albedo, ps.normal, index + 1);
          }
          view.AddWork(x, y, (float)(ctr.Work() - workBefore));
        }
      if (progress) {
        std::lock_guard<std::mutex> lock(progressMutex);
        progress(++tilesDone, tileCount);
      }
    }
  };

  std::vector<std::thread> pool;
  for (int t = 1; t < threads_; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (std::thread& t : pool) t.join();

  if (cancel && cancel->load()) return false;
  if (counters)
    for (const TraceCounters& c : perThread) *counters += c;
  return true;
}

}  // namespace mmrtm
