#include "wavefront_camera_paths.h"

#ifdef MMRTM_HAVE_SIMD
#include "camera_path_starts.h"
#include "grid_walk_lanes.h"
#include "plain_extinction.h"
#endif

namespace mmrtm {

#ifndef MMRTM_HAVE_SIMD
struct GridWalkLanes {};
struct CameraPathStarts {};
#endif

WavefrontCameraPaths::WavefrontCameraPaths()
    : walks_(std::make_unique<GridWalkLanes>()), starts_(std::make_unique<CameraPathStarts>()) {}
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

int SimdLookupLanes() {
#ifdef MMRTM_HAVE_SIMD
  return PlainExtinctionLaneCount();
#else
  return 0;
#endif
}

namespace {

#ifdef MMRTM_HAVE_SIMD
// DeltaTrack's choice at a camera path's arrival, with the path's random
// numbers and counters.
class CameraChoices : public ArrivalChoices {
 public:
  CameraChoices(const SceneView& s, std::vector<CameraPath>& paths) : s_(s), paths_(paths) {}

  bool Real(uint32_t i, float t, Vec3 p, float sigma_maj, const Classification* plain, float* tau) override {
    CameraPath& path = paths_[i];
    const Classification c = plain ? *plain : s_.classifier.Classify(path.sample.ray(t), p);
    CountLookup(c.sigma_t, sigma_maj, 1.f, path.ctr);
    if (path.choice.Real(c.sigma_t, sigma_maj, path.sample.rng, path.ctr)) {
      path.freePath.collided = true;
      path.freePath.t = t;
      path.freePath.c = c;
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

bool WavefrontCameraPaths::Faster(const SceneView& s) {
#ifdef MMRTM_HAVE_SIMD
  return Runs(s) && CameraPathStartsRun(s) && SimdLookupLanes() >= kFasterLanes;
#else
  (void)s;
  return false;
#endif
}

void WavefrontCameraPaths::Track(const SceneView& s, const std::vector<PixelSampleId>& samples,
                                 std::vector<CameraPath>& paths, LaneCounters* lanes) {
#ifdef MMRTM_HAVE_SIMD
  MMRTM_DCHECK(Runs(s));
  const size_t count = samples.size();
  paths.clear();
  walks_->Resize(count);
  walking_.clear();
  if (CameraPathStartsRun(s)) {
    CameraPathStarts& st = *starts_;
    st.Resize(count);
    for (size_t i = 0; i < count; ++i) {
      st.x[i] = samples[i].x;
      st.y[i] = samples[i].y;
      st.sampleIndex[i] = samples[i].index;
    }
    StartCameraPaths(s, st);
    const float* const indexO[3] = {st.indexO[0].data(), st.indexO[1].data(), st.indexO[2].data()};
    const float* const indexD[3] = {st.indexD[0].data(), st.indexD[1].data(), st.indexD[2].data()};
    StartWalks(s.majorants.grid, indexO, indexD, st.t0.data(), st.t1.data(), count, *walks_);
    for (uint32_t i = 0; i < (uint32_t)count; ++i) {
      const Ray ray{{st.o[0][i], st.o[1][i], st.o[2][i]}, {st.d[0][i], st.d[1][i], st.d[2][i]}};
      CameraPath& path = paths.emplace_back(CameraSample(PCG32::FromState(st.rngState[i], st.rngInc[i]),
                                                         SobolPairs::FromKey(st.sobolKey[i], st.sobolReversedIndex[i]),
                                                         true, ray, st.tMax[i]));
      if (!st.inDomain[i]) continue;
      // DrawFirstArrival with the Sobol' number.
      walks_->tau[i] = TentativeCollisionStart::OpticalDepthToArrival(st.freePathU0[i]);
      path.choice = DeltaTrackingChoice{st.freePathU1[i]};
      walking_.push_back(i);
    }
  } else {
    for (uint32_t i = 0; i < (uint32_t)count; ++i) {
      CameraPath& path = paths.emplace_back(CameraSample(s, samples[i].x, samples[i].y, samples[i].index));
      TentativeCollisionStart walk(s, path.sample.ray, path.sample.tMax, 1.f);
      if (!walk.inDomain) continue;
      float u0, u1;
      path.sample.FreePathPair(&u0, &u1);
      walk.DrawFirstArrival(path.sample.rng, u0);
      path.choice = DeltaTrackingChoice{u1};
      walks_->Set(i, walk.it.GridWalk()->State(), walk.tau);
      walking_.push_back(i);
    }
  }
  CameraChoices choices(s, paths);
  const GridTraversal traversal =
      s.majorants.kind == MajorantKind::Macrocell ? GridTraversal::Macrocell : GridTraversal::Octree;
  DeltaTrackWalks(s.classifier, s.majorants.grid, traversal, *walks_, walking_.data(), walking_.size(), choices, lanes);
  for (uint32_t i : walking_) paths[i].ctr.majorantSegments += (uint64_t)walks_->segments[i];
#else
  (void)s;
  (void)samples;
  (void)paths;
  (void)lanes;
#endif
}

}  // namespace mmrtm
