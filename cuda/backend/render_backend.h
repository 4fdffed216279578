// Backend choice: --backend auto|cpu|cuda. Auto uses CUDA when this build
// has it and a device is present, else the CPU; the absence of a driver or
// device is found once (cached) and reported once per process. An explicit
// `cuda` without a device is a BackendError, not a crash. Host-only.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cpu_renderer.h"
#include "film.h"
#include "mmrtm/counters.h"
#include "scene.h"

namespace mmrtm {

enum class Backend { Auto, Cpu, Cuda };

// "auto", "cpu", "cuda"; nullopt for anything else.
std::optional<Backend> ParseBackend(const std::string& name);

// A backend that cannot run here (no device, a build without CUDA).
class BackendError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Whether this build has the CUDA backend (MMRTM_ENABLE_CUDA).
bool CudaBackendBuilt();

// Throws BackendError when `backend` cannot run here (an explicit cuda
// without a device, or in a build without CUDA): checked before loading.
void RequireBackend(Backend backend);

class Renderer {
 public:
  virtual ~Renderer() = default;
  // "cpu, 2 thread(s)", "cuda, NVIDIA H100 ...": for progress lines and stats.
  virtual std::string Description() const = 0;
  virtual bool IsCuda() const = 0;
  // Adds `samplesPerPixel` samples of `view` (built by `scene`, whose grid
  // the CUDA backend refits on the device) to `film`. Returns false when
  // `cancel` (set from another thread) stopped the pass early: the film is
  // then partial and must be reset (the CPU backend stops between tiles; a
  // CUDA pass, short, runs to its end).
  using Progress = std::function<void(int, int)>;
  virtual bool Render(const Scene& scene, const SceneView& view, Film& film, int samplesPerPixel,
                      TraceCounters* counters, const Progress& progress, const std::atomic<bool>* cancel = nullptr) = 0;
  // Adaptive sampling: adds samples to pixel i (row-major) until it has
  // targetCounts[i]; sample indices continue from each pixel's own count.
  // Afterwards the film has per-pixel counts (Film::Adaptive).
  virtual bool RenderTo(const Scene& scene, const SceneView& view, Film& film,
                        const std::vector<uint32_t>& targetCounts, TraceCounters* counters, const Progress& progress,
                        const std::atomic<bool>* cancel = nullptr) = 0;
};

// `note` receives one-line remarks for the user (why auto chose the CPU, a
// fall-back after a GPU allocation failed). Throws BackendError for an
// explicit `cuda` that cannot run.
std::unique_ptr<Renderer> MakeRenderer(Backend backend, int threads,
                                       const std::function<void(const std::string&)>& note = nullptr);

}  // namespace mmrtm
