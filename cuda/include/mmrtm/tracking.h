// Free-path sampling and transmittance estimation.
//
// Unbiased (the default, DESIGN.md rule 5):
//   DeltaTrack: delta (Woodcock) tracking over majorant segments;
//   RatioTrack: residual ratio tracking for shadow rays (Novak et al.
//               2014), with Russian roulette on small transmittance (as
//               pbrt-v4).
// Biased baseline: RayMarch / RayMarchTransmittance, the fixed-step marching
// of ExposureRenderer (Kroes et al. 2012): it misses features thinner than
// its step and its error stops falling with more samples.
#pragma once

#include "mmrtm/counters.h"
#include "mmrtm/planted_defect.h"
#include "mmrtm/rng.h"
#include "mmrtm/scene_view.h"

namespace mmrtm {

// Ratio tracking rouletted when the running transmittance drops below this,
// surviving with kRatioSurvival. pbrt-v4 has 0.05 and 0.25. With residual
// tracking a ray's transmittance falls smoothly instead of in the steps of
// null collisions, so at 0.05 shadow rays went further than before (18.5 to
// 21.9 majorant segments a sample on the chest CT); at 0.1 the error of the
// five reference scenes is what 0.05 gives, for fewer segments
// (Documentation/performance.md, "Residual ratio tracking").
constexpr float kRatioRouletteThreshold = 0.1f;
constexpr float kRatioSurvival = 0.25f;

struct FreePathResult {
  bool collided = false;
  float t = 0.f;
  Classification c;
};

// Counts a lookup, and a violation if the (scaled) extinction there exceeds
// the majorant that the tracker was given.
MMRTM_CPU_GPU inline void CountLookup(float sigma_t, float sigma_maj, float scale, TraceCounters& ctr) {
  ++ctr.densityLookups;
  if (scale * sigma_t > sigma_maj * 1.0001f) ++ctr.majorantViolations;
}
// Classifies p (`index0`: p in proxy 0's index space), counting the lookup.
MMRTM_CPU_GPU inline Classification LookupAndCount(const SceneView& s, Vec3 p, Vec3 index0, float sigma_maj,
                                                   float scale, TraceCounters& ctr) {
  Classification c = s.classifier.Classify(p, index0);
  CountLookup(c.sigma_t, sigma_maj, scale, ctr);
  return c;
}

// The optical depth to an arrival, Exp(1), from a uniform u.
MMRTM_CPU_GPU inline float OpticalDepthToArrival(float u) { return -logf(1.f - u); }

// Walks the tentative collisions of a ray up to tMax and calls visit(t,
// classification, sigma_maj) at each until visit returns false or the ray
// ends.
//
// The optical depth to the next arrival is drawn once, Exp(1), and what a
// segment does not use up carries into the next (pbrt-v4's SampleT_maj
// draws afresh per segment instead, which the exponential's memorylessness
// also allows). The same distribution; but a segment without a collision
// costs a multiply and a compare instead of a random number and a logf, and
// an octree walk hands out about two segments per lookup.
// `uFirst`: the uniform of the first arrival when in [0, 1) (a
// low-discrepancy number), otherwise drawn from rng.
//
// segment(seg) is called first for every segment; false ends the walk.
// With `Residual` the arrivals' rate is sigma_maj - sigma_min instead (the
// residual of residual ratio tracking, which takes the control part,
// exp(-sigma_min * length), in segment), and visit gets (classification,
// residual segment), whose sigma_maj is that rate.
template <bool Residual = false, typename Visit, typename Segment>
MMRTM_CPU_GPU inline void SampleTentativeCollisions(const SceneView& s, const Ray& ray, float tMax, float scale,
                                                    PCG32& rng, TraceCounters& ctr, Visit visit, Segment segment,
                                                    float uFirst = -1.f) {
  Ray indexRay;
  float t0, t1;
  if (!s.DomainInterval(ray, tMax, &indexRay, &t0, &t1)) return;
  MajorantIterator it = s.majorants.Begin(indexRay, t0, t1, scale);
  float tau = OpticalDepthToArrival(uFirst >= 0.f ? uFirst : rng.Uniform());
  RayMajorantSegment seg;
  while (it.Next(&seg)) {
    ++ctr.majorantSegments;
    if constexpr (Residual) {
      if (Planted(Defect::ShadowLastSegment) && seg.tMax >= t1) return;
      if (!segment(seg)) return;
      seg.sigma_maj -= seg.sigma_min;
    }
    if (seg.sigma_maj <= 0.f) continue;
    for (float t = seg.tMin;;) {
      const float tauLeft = (seg.tMax - t) * seg.sigma_maj;  // in this segment
      if (tau >= tauLeft) {
        tau -= tauLeft;
        break;
      }
      t += tau / seg.sigma_maj;  // below tMax but for rounding, which lands on this node's face
      // The point also in proxy 0's index space, from the index ray: the
      // proxies on proxy 0's grid are sampled there (Classifier::onProxy0Grid).
      Classification c =
          LookupAndCount(s, ray(t), indexRay(t), Residual ? seg.sigma_maj + seg.sigma_min : seg.sigma_maj, scale, ctr);
      if constexpr (Residual) {
        if (!visit(c, seg)) return;
      } else {
        if (!visit(t, c, seg.sigma_maj)) return;
      }
      tau = OpticalDepthToArrival(rng.Uniform());
    }
  }
}

// Delta tracking's choice at an arrival: real with probability
// sigma_t / sigma_maj. The first choice's uniform may be given (a
// low-discrepancy number, in [0, 1)); the others are drawn from rng.
struct DeltaTrackingChoice {
  float firstU = -1.f;  // negative: none (left)

  MMRTM_CPU_GPU bool Real(float sigma_t, float sigma_maj, PCG32& rng, TraceCounters& ctr) {
    const float u = firstU >= 0.f ? firstU : rng.Uniform();
    firstU = -1.f;
    if (u * sigma_maj < sigma_t) {
      ++ctr.realCollisions;
      return true;
    }
    ++ctr.nullCollisions;
    return false;
  }
};

// Delta tracking: a tentative collision is real with probability
// sigma_t / sigma_maj. `first`, when given, holds the uniforms of the first
// arrival and of its real-or-null choice (a low-discrepancy pair).
MMRTM_CPU_GPU inline FreePathResult DeltaTrack(const SceneView& s, const Ray& ray, float tMax, PCG32& rng,
                                               TraceCounters& ctr, const float* first = nullptr) {
  FreePathResult r;
  DeltaTrackingChoice choice{first ? first[1] : -1.f};
  SampleTentativeCollisions(
      s, ray, tMax, 1.f, rng, ctr,
      [&](float t, const Classification& c, float sigma_maj) {
        if (choice.Real(c.sigma_t, sigma_maj, rng, ctr)) {
          r.collided = true;
          r.t = t;
          r.c = c;
          return false;
        }
        return true;
      },
      [](const RayMajorantSegment&) { return true; }, first ? first[0] : -1.f);
  return r;
}

// Ratio tracking: transmittance along ray up to tMax, with sigma_t scaled by
// `scale`, as the product of the null-collision probabilities. `uFirst` as
// in SampleTentativeCollisions.
//
// Residual ratio tracking (Novak et al. 2014): where the grid knows a lower
// bound sigma_min of the extinction over a segment, exp(-sigma_min * length)
// is the control part, exact, and only the residual sigma_t - sigma_min is
// tracked, at rate sigma_maj - sigma_min: fewer lookups, and no noise where
// the extinction is nearly constant.
MMRTM_CPU_GPU inline float RatioTrack(const SceneView& s, const Ray& ray, float tMax, float scale, PCG32& rng,
                                      TraceCounters& ctr, float uFirst = -1.f) {
  ++ctr.shadowRays;
  float T = 1.f;
  auto roulette = [&]() {
    if (T <= 0.f) return false;
    if (T < kRatioRouletteThreshold) {
      if (rng.Uniform() >= kRatioSurvival) {
        T = 0.f;
        return false;
      }
      T /= kRatioSurvival;
    }
    return true;
  };
  SampleTentativeCollisions<true>(
      s, ray, tMax, scale, rng, ctr,
      [&](const Classification& c, const RayMajorantSegment& residual) {
        // The residual's null-collision probability (in [0, 1] but for
        // rounding at the bounds).
        T *= Clamp(1.f - (scale * c.sigma_t - residual.sigma_min) / residual.sigma_maj, 0.f, 1.f);
        return roulette();
      },
      [&](const RayMajorantSegment& seg) {
        if (seg.sigma_min <= 0.f) return true;
        T *= expf(-seg.sigma_min * (seg.tMax - seg.tMin));  // the control part, exact
        return roulette();
      },
      uFirst);
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
    Classification c = LookupAndCount(s, ray(t), indexRay(t), kInfinity, 1.f, ctr);
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
    depth += LookupAndCount(s, ray(t), indexRay(t), kInfinity, 1.f, ctr).sigma_t * step;
  return expf(-scale * depth);
}

MMRTM_CPU_GPU inline FreePathResult SampleFreePath(const SceneView& s, const Ray& ray, float tMax, PCG32& rng,
                                                   TraceCounters& ctr, const float* first = nullptr) {
  return s.settings.estimator == Estimator::RayMarching ? RayMarch(s, ray, tMax, rng, ctr)
                                                        : DeltaTrack(s, ray, tMax, rng, ctr, first);
}

MMRTM_CPU_GPU inline float Transmittance(const SceneView& s, const Ray& ray, float tMax, PCG32& rng, TraceCounters& ctr,
                                         float uFirst = -1.f) {
  float scale = s.settings.shadowExtinctionScale;
  return s.settings.estimator == Estimator::RayMarching ? RayMarchTransmittance(s, ray, tMax, scale, rng, ctr)
                                                        : RatioTrack(s, ray, tMax, scale, rng, ctr, uFirst);
}

}  // namespace mmrtm
