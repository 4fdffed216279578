// Free-path sampling and transmittance estimation.
//
// Unbiased (the default, DESIGN.md rule 5):
//   DeltaTrack: delta (Woodcock) tracking over majorant segments;
//   RatioTrack: ratio tracking for shadow rays, with Russian roulette on
//               small transmittance (as pbrt-v4).
// Biased baseline: RayMarch / RayMarchTransmittance, the fixed-step marching
// of ExposureRenderer (Kroes et al. 2012): it misses features thinner than
// its step and its error stops falling with more samples.
#pragma once

#include "mmrtm/counters.h"
#include "mmrtm/rng.h"
#include "mmrtm/scene_view.h"

namespace mmrtm {

// Ratio tracking rouletted when the running transmittance drops below this,
// surviving with kRatioSurvival (pbrt-v4's values).
constexpr float kRatioRouletteThreshold = 0.05f;
constexpr float kRatioSurvival = 0.25f;

struct FreePathResult {
  bool collided = false;
  float t = 0.f;
  Classification c;
};

// Classifies p, counting the lookup, and a violation if the (scaled)
// extinction there exceeds the majorant that the tracker was given.
MMRTM_CPU_GPU inline Classification LookupAndCount(const SceneView& s, Vec3 p, float sigma_maj, float scale,
                                                    TraceCounters& ctr) {
  Classification c = s.classifier.Classify(p);
  ++ctr.densityLookups;
  if (scale * c.sigma_t > sigma_maj * 1.0001f) ++ctr.majorantViolations;
  return c;
}

// Walks the tentative collisions of a ray up to tMax: the arrivals of a
// Poisson process whose rate is each majorant segment's sigma_maj. Calls
// visit(t, classification, sigma_maj) at each until visit returns false or
// the ray ends. `scale` multiplies the extinction and the majorants.
//
// The optical depth to the next arrival is drawn once, Exp(1), and what a
// segment does not use up carries into the next (pbrt-v4's SampleT_maj
// draws afresh per segment instead, which the exponential's memorylessness
// also allows). The same distribution; but a segment without a collision
// costs a multiply and a compare instead of a random number and a logf, and
// an octree walk hands out about two segments per lookup.
template <typename Visit>
MMRTM_CPU_GPU inline void SampleTentativeCollisions(const SceneView& s, const Ray& ray, float tMax, float scale,
                                                    PCG32& rng, TraceCounters& ctr, Visit visit) {
  Ray indexRay;
  float t0, t1;
  if (!s.DomainInterval(ray, tMax, &indexRay, &t0, &t1)) return;
  MajorantIterator it = s.majorants.Begin(indexRay, t0, t1, scale);
  RayMajorantSegment seg;
  float tau = -logf(1.f - rng.Uniform());  // optical depth to the next arrival
  while (it.Next(&seg)) {
    ++ctr.majorantSegments;
    if (seg.sigma_maj <= 0.f) continue;
    for (float t = seg.tMin;;) {
      const float tauLeft = (seg.tMax - t) * seg.sigma_maj;  // in this segment
      if (tau >= tauLeft) {
        tau -= tauLeft;
        break;
      }
      t += tau / seg.sigma_maj;  // below tMax but for rounding, which lands on this node's face
      Classification c = LookupAndCount(s, ray(t), seg.sigma_maj, scale, ctr);
      if (!visit(t, c, seg.sigma_maj)) return;
      tau = -logf(1.f - rng.Uniform());
    }
  }
}

// Delta tracking: a tentative collision is real with probability
// sigma_t / sigma_maj.
MMRTM_CPU_GPU inline FreePathResult DeltaTrack(const SceneView& s, const Ray& ray, float tMax, PCG32& rng,
                                               TraceCounters& ctr) {
  FreePathResult r;
  SampleTentativeCollisions(s, ray, tMax, 1.f, rng, ctr, [&](float t, const Classification& c, float sigma_maj) {
    if (rng.Uniform() * sigma_maj < c.sigma_t) {
      ++ctr.realCollisions;
      r.collided = true;
      r.t = t;
      r.c = c;
      return false;
    }
    ++ctr.nullCollisions;
    return true;
  });
  return r;
}

// Ratio tracking: transmittance along ray up to tMax, with sigma_t scaled by
// `scale`, as the product of the null-collision probabilities.
MMRTM_CPU_GPU inline float RatioTrack(const SceneView& s, const Ray& ray, float tMax, float scale, PCG32& rng,
                                      TraceCounters& ctr) {
  ++ctr.shadowRays;
  float T = 1.f;
  SampleTentativeCollisions(s, ray, tMax, scale, rng, ctr, [&](float, const Classification& c, float sigma_maj) {
    T *= Max(0.f, 1.f - scale * c.sigma_t / sigma_maj);
    if (T < kRatioRouletteThreshold) {
      if (rng.Uniform() >= kRatioSurvival) {
        T = 0.f;
        return false;
      }
      T /= kRatioSurvival;
    }
    return true;
  });
  return T;
}

// Ray marching with a jittered start: the collision is where the optical
// depth, summed in steps of `step`, first exceeds -ln(1 - u).
MMRTM_CPU_GPU inline FreePathResult RayMarch(const SceneView& s, const Ray& ray, float tMax, PCG32& rng,
                                             TraceCounters& ctr) {
  FreePathResult r;
  Ray indexRay;
  float t0, t1;
  if (!s.DomainInterval(ray, tMax, &indexRay, &t0, &t1)) return r;
  float step = s.settings.rayMarchStep;
  float target = -logf(1.f - rng.Uniform());
  float depth = 0.f;
  for (float t = t0 + step * rng.Uniform(); t < t1; t += step) {
    Classification c = LookupAndCount(s, ray(t), kInfinity, 1.f, ctr);
    depth += c.sigma_t * step;
    if (depth >= target) {
      ++ctr.realCollisions;
      r.collided = true;
      r.t = t;
      r.c = c;
      return r;
    }
  }
  return r;
}

MMRTM_CPU_GPU inline float RayMarchTransmittance(const SceneView& s, const Ray& ray, float tMax, float scale,
                                                 PCG32& rng, TraceCounters& ctr) {
  ++ctr.shadowRays;
  Ray indexRay;
  float t0, t1;
  if (!s.DomainInterval(ray, tMax, &indexRay, &t0, &t1)) return 1.f;
  float step = s.settings.rayMarchStep;
  float depth = 0.f;
  for (float t = t0 + step * rng.Uniform(); t < t1; t += step)
    depth += LookupAndCount(s, ray(t), kInfinity, 1.f, ctr).sigma_t * step;
  return expf(-scale * depth);
}

MMRTM_CPU_GPU inline FreePathResult SampleFreePath(const SceneView& s, const Ray& ray, float tMax, PCG32& rng,
                                                   TraceCounters& ctr) {
  return s.settings.estimator == Estimator::RayMarching ? RayMarch(s, ray, tMax, rng, ctr)
                                                        : DeltaTrack(s, ray, tMax, rng, ctr);
}

MMRTM_CPU_GPU inline float Transmittance(const SceneView& s, const Ray& ray, float tMax, PCG32& rng,
                                         TraceCounters& ctr) {
  float scale = s.settings.shadowExtinctionScale;
  return s.settings.estimator == Estimator::RayMarching ? RayMarchTransmittance(s, ray, tMax, scale, rng, ctr)
                                                        : RatioTrack(s, ray, tMax, scale, rng, ctr);
}

}  // namespace mmrtm
