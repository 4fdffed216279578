#include "wavefront_camera_paths.h"

#ifdef MMRTM_HAVE_SIMD
#include "grid_walk_lanes.h"
#include "plain_extinction.h"
#endif

namespace mmrtm {

#ifndef MMRTM_HAVE_SIMD
struct GridWalkLanes {};
#endif

WavefrontCameraPaths::WavefrontCameraPaths() : walks_(std::make_unique<GridWalkLanes>()) {}
WavefrontCameraPaths::~WavefrontCameraPaths() = default;

bool SimdLookupsBuilt() {
#ifdef MMRTM_HAVE_SIMD
  return true;
#else
  return false;
#endif
}

const char* SimdLookupTarget() {
#ifdef MMRTM_HAVE_SIMD
  return PlainExtinctionTarget();
#else
  return "";
#endif
}

namespace {

#ifdef MMRTM_HAVE_SIMD
// DeltaTrack's choice at a camera path's arrival, with the path's random
// numbers and counters.
class CameraChoices : public ArrivalChoices {
 public:
  CameraChoices(const SceneView& s, std::vector<CameraPath>& paths) : s_(s), paths_(paths) {}

  bool Real(uint32_t i, float t, Vec3 p, float sigma_maj, const float* sigma_t, float* tau) override {
    CameraPath& path = paths_[i];
    Classification c;
    if (!sigma_t) c = s_.classifier.Classify(path.sample.ray(t), p);
    const float extinction = sigma_t ? *sigma_t : c.sigma_t;
    CountLookup(extinction, sigma_maj, 1.f, path.ctr);
    if (path.choice.Real(extinction, sigma_maj, path.sample.rng, path.ctr)) {
      path.freePath.collided = true;
      path.freePath.t = t;
      // The lanes gave a plain scene's extinction only: the collision's
      // whole classification is one more scalar lookup (one a path).
      path.freePath.c = sigma_t ? s_.classifier.Classify(path.sample.ray(t), p) : c;
      return true;
    }
    *tau = TentativeCollisionStart::OpticalDepthToArrival(path.sample.rng.Uniform());
    return false;
  }

 private:
  const SceneView& s_;
  std::vector<CameraPath>& paths_;
};
#endif

}  // namespace

bool WavefrontCameraPaths::Runs(const SceneView& s) {
#ifdef MMRTM_HAVE_SIMD
  return s.settings.estimator == Estimator::DeltaTracking && s.majorants.kind != MajorantKind::Global &&
         GridWalkLanesFit(s.majorants.grid) && PlainLookupsFit(s.classifier);
#else
  (void)s;
  return false;
#endif
}

void WavefrontCameraPaths::Track(const SceneView& s, std::vector<CameraPath>& paths, LaneCounters* lanes) {
#ifdef MMRTM_HAVE_SIMD
  MMRTM_DCHECK(Runs(s));
  walks_->Resize(paths.size());
  walking_.clear();
  for (uint32_t i = 0; i < (uint32_t)paths.size(); ++i) {
    CameraPath& path = paths[i];
    path.freePath = FreePathResult();
    if (!path.walk.inDomain) continue;
    float u0, u1;
    path.sample.FreePathPair(&u0, &u1);
    path.walk.DrawFirstArrival(path.sample.rng, u0);
    path.choice = DeltaTrackingChoice{u1};
    walks_->Set(i, path.walk.it.GridWalk()->State(), path.walk.tau);
    walking_.push_back(i);
  }
  CameraChoices choices(s, paths);
  const GridTraversal traversal =
      s.majorants.kind == MajorantKind::Macrocell ? GridTraversal::Macrocell : GridTraversal::Octree;
  DeltaTrackWalks(s.classifier, s.majorants.grid, traversal, *walks_, walking_.data(), walking_.size(), choices, lanes);
  for (uint32_t i : walking_) paths[i].ctr.majorantSegments += (uint64_t)walks_->segments[i];
#else
  (void)s;
  (void)paths;
  (void)lanes;
#endif
}

}  // namespace mmrtm
