// The CUDA backend: the same per-pixel integrator as the CPU backend
// (mmrtm/integrator.h), run by one thread per pixel, on a scene uploaded to
// device memory by RelocateSceneView. The accumulation (mean and M2 per
// pixel) stays on the device between renders; the film comes back once per
// Render. The majorant refit runs on the device from the grid's summaries
// (mmrtm/majorant_refit.h), with the CPU refit's per-leaf function.
//
// No CUDA type in this header: applications include it with a host compiler.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "film.h"
#include "majorant_grid.h"
#include "mmrtm/counters.h"
#include "mmrtm/scene_view.h"
#include "scene_uploads.h"

namespace mmrtm {

class GpuRenderer {
 public:
  // Throws CudaError (a std::runtime_error) when no CUDA device is usable.
  GpuRenderer();
  ~GpuRenderer();
  GpuRenderer(const GpuRenderer&) = delete;
  GpuRenderer& operator=(const GpuRenderer&) = delete;

  // Uploads the parts of the scene that `uploads` asks for (a
  // SceneUploadPlanner's answer; everything by default); the others keep
  // the device copies of the last call, which must have the same sizes.
  // Voxels go up also when a proxy's address or size changed. Checks the
  // free device memory first and throws DeviceMemoryError with the sizes
  // when it is short.
  void SetScene(const SceneView& view, const SceneUploads& uploads = SceneUploads());

  // Refits the uploaded scene's majorant grid on the device: the leaves in
  // parallel, then each upper level. `grid` is the host grid the scene was
  // built with (its summaries go up when `summariesChanged`), `classifier`
  // the host classifier (its TFs give the per-bin tables). The caller
  // refits only after uploading the majorants (SceneUploads::majorants).
  void Refit(const MajorantGrid& grid, const Classifier& classifier, bool summariesChanged);
  // The device majorants, level after level, and the minorant bytes (for tests).
  std::vector<float> DownloadMajorants() const;
  std::vector<uint8_t> DownloadMinorants() const;

  // Adds `samplesPerPixel` samples to every pixel, accumulating on the
  // device, and copies the accumulation into `film` at the end. Sample
  // indices continue from film.Samples(), so a CPU and a GPU render of one
  // seed take the same random numbers.
  using Progress = std::function<void(int, int)>;
  void Render(Film& film, int samplesPerPixel, TraceCounters* counters = nullptr, const Progress& progress = nullptr);
  // Adaptive sampling: adds samples to pixel i until it has targetCounts[i]
  // (indices continue from each pixel's own count, as on the CPU). The film
  // goes up and comes back on every call; `film` may be uniform or adaptive.
  void RenderTo(Film& film, const std::vector<uint32_t>& targetCounts, TraceCounters* counters = nullptr,
                const Progress& progress = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmrtm
