// One image tile on the CPU's SIMD backend: the tile's pixel samples, in
// batches, have their camera rays started and tracked together
// (wavefront_camera_paths.h), then each path goes on in the scalar
// integrator (Li, given its free path). Samples are added to the film in
// the scalar loop's order (pixel by pixel, sample index by index), so the
// film holds the scalar backend's bits.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "film.h"
#include "wavefront_camera_paths.h"

namespace mmrtm {

class WavefrontTile {
 public:
  // Renders sample indices [film.PixelSamples(x, y), end(pixel index, that
  // count)) of the pixels [x0, x1) x [y0, y1), adding the work to `ctr`
  // and to the film's per-pixel work (as the scalar loop does).
  void Render(const SceneView& s, const Film& film, const FilmView& view, int x0, int y0, int x1, int y1,
              const std::function<uint32_t(size_t, uint32_t)>& end, TraceCounters& ctr, LaneCounters* lanes);

  // Paths tracked together: enough that the lanes, refilled as rays
  // collide, stay full but for the batch's last rays; few enough for their
  // state (about 0.4 KiB each: the path, its start and its walk) to stay
  // in the core's L2 cache.
  static constexpr size_t kBatchPaths = 1024;

 private:
  void Finish(const SceneView& s, const FilmView& view, TraceCounters& ctr, LaneCounters* lanes);

  std::vector<PixelSampleId> samples_;
  std::vector<uint32_t> inTile_;  // each sample's pixel's index in the tile
  std::vector<CameraPath> paths_;
  std::vector<uint64_t> work_;  // each pixel of the tile
  WavefrontCameraPaths tracker_;
};

}  // namespace mmrtm
