// The CPU backend: a thread pool over image tiles running the shared
// per-pixel integrator. Tiles are handed out dynamically, but each pixel's
// samples depend only on (seed, pixel, sample index), so the image is the
// same to the last bit at any thread count (DESIGN.md rule 2).
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "film.h"
#include "mmrtm/counters.h"
#include "mmrtm/scene_view.h"
#include "wavefront_camera_paths.h"

namespace mmrtm {

// --simd auto|on|off. On: the SIMD backend where it runs (a build with
// Highway, delta tracking over a majorant grid, no intensity projection:
// WavefrontCameraPaths::Runs): a tile's camera rays delta-tracked in SIMD
// lanes (wavefront_camera_paths.h). Off: the scalar backend. Both give the
// same image to the last bit. Auto: the faster of the two for the scene
// on this CPU (WavefrontCameraPaths::Faster: the SIMD backend where the
// lanes start the camera paths too and have 8 or more floats, AVX2 and
// AVX-512; Documentation/performance.md, "SIMD lanes: the camera stage").
enum class SimdMode { Off, Auto, On };
std::optional<SimdMode> ParseSimdMode(const std::string& name);

class CpuRenderer {
 public:
  // threads <= 0: one per hardware thread. `simd` Auto takes the
  // environment's MMRTM_CPU_SIMD (on, off) where it is set.
  explicit CpuRenderer(int threads = 0, SimdMode simd = SimdMode::Auto);
  int Threads() const { return threads_; }
  // Whether a render of `scene` runs the SIMD backend.
  bool UsesSimd(const SceneView& scene) const;
  // "cpu, 2 thread(s), SIMD AVX3" (or "scalar"): what renders `scene`; without
  // one, what this mode runs where it can ("SIMD AVX3 where faster" for auto).
  std::string Description(const SceneView* scene = nullptr) const;
  // Where the renders that follow add their lanes' occupancy (null: not counted).
  void CountLanes(LaneCounters* lanes) { lanes_ = lanes; }

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
  SimdMode simd_;
  LaneCounters* lanes_ = nullptr;
};

}  // namespace mmrtm
