#include "wavefront_tile.h"

namespace mmrtm {

void WavefrontTile::Render(const SceneView& s, const Film& film, const FilmView& view, int x0, int y0, int x1, int y1,
                           const std::function<uint32_t(size_t, uint32_t)>& end, TraceCounters& ctr,
                           LaneCounters* lanes) {
  const int width = film.Width();
  samples_.reserve(kBatchPaths);
  paths_.reserve(kBatchPaths);  // paths are built in place, never moved
  work_.assign((size_t)(x1 - x0) * (y1 - y0), 0);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const uint32_t inTile = (uint32_t)((x - x0) + (x1 - x0) * (y - y0));
      const uint32_t first = film.PixelSamples(x, y), last = end((size_t)y * width + x, first);
      for (uint32_t index = first; index < last; ++index) {
        if (samples_.size() == kBatchPaths) Finish(s, view, ctr, lanes);
        samples_.push_back({x, y, index});
        inTile_.push_back(inTile);
        ++ctr.paths;
        ++work_[inTile];
      }
    }
  Finish(s, view, ctr, lanes);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) view.AddWork(x, y, (float)work_[(size_t)(x - x0) + (size_t)(x1 - x0) * (y - y0)]);
}

void WavefrontTile::Finish(const SceneView& s, const FilmView& view, TraceCounters& ctr, LaneCounters* lanes) {
  tracker_.Track(s, samples_, paths_, lanes);
  for (size_t i = 0; i < paths_.size(); ++i) {
    CameraPath& path = paths_[i];
    const PixelSampleId& o = samples_[i];
    ctr += path.ctr;
    const uint64_t before = ctr.Work();
    const PixelSample ps =
        Li(s, path.sample.ray, path.sample.rng, ctr, path.sample.tMax, path.sample.Pairs(), &path.freePath);
    view.AddSample(o.x, o.y, ps.L, ps.alpha, o.index + 1);
    view.AddDenoiserInputs(o.x, o.y, ps.L, ps.albedo, ps.normal, o.index + 1);
    work_[inTile_[i]] += path.ctr.Work() + (ctr.Work() - before);
  }
  samples_.clear();
  inTile_.clear();
  paths_.clear();
}

}  // namespace mmrtm
