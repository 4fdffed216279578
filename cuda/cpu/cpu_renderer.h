// The CPU backend: a thread pool over image tiles running the shared
// per-pixel integrator. Tiles are handed out dynamically, but each pixel's
// samples depend only on (seed, pixel, sample index), so the image is the
// same to the last bit at any thread count (DESIGN.md rule 2).
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "film.h"
#include "mmrtm/counters.h"
#include "mmrtm/scene_view.h"

namespace mmrtm {

class CpuRenderer {
 public:
  // threads <= 0: one per hardware thread.
  explicit CpuRenderer(int threads = 0);
  int Threads() const { return threads_; }
  // "cpu, 2 thread(s)": for progress lines and stats.
  std::string Description() const;

  // Called with (tiles done, tiles total) as tiles finish, from one thread at a time.
  using Progress = std::function<void(int, int)>;

  // Adds `samplesPerPixel` samples to every pixel of `film` (sample indices
  // continue from film.Samples()) and adds the work done to `counters`.
  // When `cancel` becomes true (from another thread) no further tile is
  // started and false is returned: the film then holds a partial pass and
  // must be reset before it is used again.
  bool Render(const SceneView& scene, Film& film, int samplesPerPixel, TraceCounters* counters = nullptr,
              const Progress& progress = nullptr, const std::atomic<bool>* cancel = nullptr) const;
  // Adaptive sampling: adds samples to pixel i (row-major) until it has
  // targetCounts[i] (none where it has that many already). Sample indices
  // continue from each pixel's own count, so the image depends only on the
  // counts, not on the passes or threads that produced them.
  bool RenderTo(const SceneView& scene, Film& film, const std::vector<uint32_t>& targetCounts,
                TraceCounters* counters = nullptr, const Progress& progress = nullptr,
                const std::atomic<bool>* cancel = nullptr) const;

  static constexpr int kTileSize = 16;

 private:
  // Renders sample indices [film.PixelSamples(x, y), end(pixel index)) of
  // every pixel, over tiles; the caller updates the film's counts.
  bool RenderRanges(const SceneView& scene, Film& film, const std::function<uint32_t(size_t, uint32_t)>& end,
                    TraceCounters* counters, const Progress& progress, const std::atomic<bool>* cancel) const;
  int threads_;
};

}  // namespace mmrtm
