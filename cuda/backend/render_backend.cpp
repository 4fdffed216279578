#include "render_backend.h"

#include <atomic>
#include <cstdio>

#include "cpu_renderer.h"
#if MMRTM_HAVE_CUDA
#include "cuda_device.h"
#include "device_buffer.h"
#include "gpu_renderer.h"
#endif

namespace mmrtm {
namespace {

class CpuBackend : public Renderer {
 public:
  explicit CpuBackend(int threads) : cpu_(threads) {}
  std::string Description() const override { return cpu_.Description(); }
  bool IsCuda() const override { return false; }
  bool Render(const Scene&, const SceneView& view, Film& film, int spp, TraceCounters* counters,
              const Progress& progress, const std::atomic<bool>* cancel) override {
    return cpu_.Render(view, film, spp, counters, progress, cancel);
  }
  bool RenderTo(const Scene&, const SceneView& view, Film& film, const std::vector<uint32_t>& targetCounts,
                TraceCounters* counters, const Progress& progress, const std::atomic<bool>* cancel) override {
    return cpu_.RenderTo(view, film, targetCounts, counters, progress, cancel);
  }

 private:
  CpuRenderer cpu_;
};

#if MMRTM_HAVE_CUDA
class CudaBackend : public Renderer {
 public:
  // With `fallbackThreads` >= 0 (auto), a scene too large for the device is
  // rendered on the CPU instead, with a note; otherwise the error stands.
  CudaBackend(int fallbackThreads, std::function<void(const std::string&)> note)
      : fallbackThreads_(fallbackThreads), note_(std::move(note)) {}
  std::string Description() const override {
    if (fallback_) return fallback_->Description() + " (fallen back from cuda)";
    return "cuda, " + CudaDevice().name;
  }
  bool IsCuda() const override { return !fallback_; }
  bool Render(const Scene& scene, const SceneView& view, Film& film, int spp, TraceCounters* counters,
              const Progress& progress, const std::atomic<bool>* cancel) override {
    if (film.Adaptive()) {  // per-pixel counts: the same samples as RenderTo gives
      std::vector<uint32_t> targets((size_t)film.Width() * film.Height());
      for (size_t i = 0; i < targets.size(); ++i)
        targets[i] = film.PixelSamples((int)(i % film.Width()), (int)(i / film.Width())) + (uint32_t)spp;
      return RenderTo(scene, view, film, targets, counters, progress, cancel);
    }
    return Run(
        scene, view, [&] { gpu_.Render(film, spp, counters, progress); },
        [&](Renderer& cpu) { return cpu.Render(scene, view, film, spp, counters, progress, cancel); });
  }
  bool RenderTo(const Scene& scene, const SceneView& view, Film& film, const std::vector<uint32_t>& targetCounts,
                TraceCounters* counters, const Progress& progress, const std::atomic<bool>* cancel) override {
    return Run(
        scene, view, [&] { gpu_.RenderTo(film, targetCounts, counters, progress); },
        [&](Renderer& cpu) { return cpu.RenderTo(scene, view, film, targetCounts, counters, progress, cancel); });
  }

 private:
  // Uploads what changed in the view since the last call (nothing for an
  // unchanged scene or a camera move: the camera and settings travel with
  // each launch), refits on the device after new majorants, and runs
  // `onDevice`; a scene too large for the device goes to `onCpu` with a CPU
  // backend instead.
  template <typename OnDevice, typename OnCpu>
  bool Run(const Scene& scene, const SceneView& view, const OnDevice& onDevice, const OnCpu& onCpu) {
    if (fallback_) return onCpu(*fallback_);
    try {
      const SceneUploads uploads = uploads_.Plan(scene, view);
      gpu_.SetScene(view, uploads);
      const MajorantGrid* grid = scene.Grid();
      // (Without minorants, as while cropping, the host's majorants went up as they are.)
      if (uploads.majorants && grid && view.majorants.kind != MajorantKind::Global && view.majorants.grid.minorants &&
          scene.render.accelerator.grid.summary == SummaryMode::CellRanges)
        gpu_.Refit(*grid, view.classifier, uploads.summaries);
      onDevice();
      return true;
    } catch (const DeviceMemoryError& e) {
      uploads_.Forget();
      if (fallbackThreads_ < 0) throw;
      if (note_) note_(std::string(e.what()) + "; rendering on the CPU instead");
      fallback_ = std::make_unique<CpuBackend>(fallbackThreads_);
      return onCpu(*fallback_);
    } catch (...) {
      uploads_.Forget();
      throw;
    }
  }

  GpuRenderer gpu_;
  int fallbackThreads_;
  std::function<void(const std::string&)> note_;
  std::unique_ptr<CpuBackend> fallback_;
  SceneUploadPlanner uploads_;
};
#endif

}  // namespace

std::optional<Backend> ParseBackend(const std::string& name) {
  if (name == "auto") return Backend::Auto;
  if (name == "cpu") return Backend::Cpu;
  if (name == "cuda") return Backend::Cuda;
  return std::nullopt;
}

bool CudaBackendBuilt() { return MMRTM_HAVE_CUDA != 0; }

void RequireBackend(Backend backend) {
  if (backend != Backend::Cuda) return;
#if MMRTM_HAVE_CUDA
  if (!CudaDevice().available) throw BackendError("--backend cuda: " + CudaDevice().reason);
#else
  throw BackendError("--backend cuda: this build has no CUDA backend (configure with MMRTM_ENABLE_CUDA=ON and nvcc)");
#endif
}

std::unique_ptr<Renderer> MakeRenderer(Backend backend, int threads,
                                       const std::function<void(const std::string&)>& note) {
  if (backend == Backend::Cpu) return std::make_unique<CpuBackend>(threads);
#if MMRTM_HAVE_CUDA
  const CudaDeviceStatus& device = CudaDevice();
  if (device.available) return std::make_unique<CudaBackend>(backend == Backend::Auto ? threads : -1, note);
  RequireBackend(backend);
  static std::atomic<bool> reported{false};
  if (note && !reported.exchange(true)) note(device.reason + "; rendering on the CPU");
#else
  RequireBackend(backend);
#endif
  return std::make_unique<CpuBackend>(threads);
}

}  // namespace mmrtm
