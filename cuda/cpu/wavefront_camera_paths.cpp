#include "wavefront_camera_paths.h"

#ifdef MMRTM_HAVE_SIMD
#include "plain_extinction.h"
#endif

namespace mmrtm {

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

void WavefrontCameraPaths::Track(const SceneView& s, std::vector<CameraPath>& paths, bool simd, LaneCounters* lanes) {
  walking_.clear();
  for (uint32_t i = 0; i < (uint32_t)paths.size(); ++i) {
    CameraPath& path = paths[i];
    path.freePath = FreePathResult();
    if (!path.walk.InDomain()) continue;
    float u0, u1;
    path.sample.FreePathPair(&u0, &u1);
    path.walk.Start(path.sample.rng, u0);
    path.choice = DeltaTrackingChoice{u1};
    walking_.push_back(i);
  }
  while (!walking_.empty()) {
    // Each walking path to its next arrival; a path whose ray ends has no
    // collision.
    arrived_.clear();
    x_.clear();
    y_.clear();
    z_.clear();
    for (uint32_t i : walking_) {
      CameraPath& path = paths[i];
      if (!path.walk.Next(path.ctr)) continue;
      const Vec3 p = path.walk.IndexPoint();
      arrived_.push_back(i);
      x_.push_back(p.x);
      y_.push_back(p.y);
      z_.push_back(p.z);
    }
    Lookup(s, paths, simd, lanes);
    // The choices; the paths that go on walk the next round.
    walking_.clear();
    for (size_t k = 0; k < arrived_.size(); ++k) {
      CameraPath& path = paths[arrived_[k]];
      const float sigma_maj = path.walk.Majorant();
      CountLookup(sigma_t_[k], sigma_maj, 1.f, path.ctr);
      if (path.choice.Real(sigma_t_[k], sigma_maj, path.sample.rng, path.ctr)) {
        const float t = path.walk.T();
        path.freePath.collided = true;
        path.freePath.t = t;
        // A plain scene's lanes gave the extinction only: the collision's
        // whole classification, one more scalar lookup (about one a path).
        path.freePath.c =
            classified_.empty() ? s.classifier.Classify(path.sample.ray(t), path.walk.IndexPoint()) : classified_[k];
        continue;
      }
      path.walk.DrawNextArrival(path.sample.rng);
      walking_.push_back(arrived_[k]);
    }
  }
}

void WavefrontCameraPaths::Lookup(const SceneView& s, const std::vector<CameraPath>& paths, bool simd,
                                  LaneCounters* lanes) {
  const size_t n = arrived_.size();
  sigma_t_.resize(n);
  classified_.clear();
#ifdef MMRTM_HAVE_SIMD
  if (simd && s.classifier.plain) {
    PlainExtinctionSimd(s.classifier, x_.data(), y_.data(), z_.data(), n, sigma_t_.data());
    if (lanes) {
      const size_t width = PlainExtinctionLaneCount();
      ++lanes->calls;
      lanes->items += n;
      lanes->lanes += (n + width - 1) / width * width;
    }
    return;
  }
#else
  (void)simd;
  (void)lanes;
#endif
  // One point at a time, as the scalar tracker looks up (the world point
  // serves cropping).
  classified_.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const CameraPath& path = paths[arrived_[k]];
    classified_[k] = s.classifier.Classify(path.sample.ray(path.walk.T()), Vec3{x_[k], y_[k], z_[k]});
    sigma_t_[k] = classified_[k].sigma_t;
  }
}

}  // namespace mmrtm
