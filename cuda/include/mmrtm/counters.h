// Work counters kept beside the tracker, so every benchmark can report
// density lookups, real and null collisions and majorant segments.
#pragma once

#include "mmrtm/defs.h"

namespace mmrtm {

struct TraceCounters {
  uint64_t paths = 0;               // camera paths (pixel samples)
  uint64_t densityLookups = 0;      // classifications for free paths and shadow rays
  uint64_t realCollisions = 0;      // real collisions of free-path sampling
  uint64_t nullCollisions = 0;      // null collisions of free-path sampling
  uint64_t shadowRays = 0;          // transmittance estimates
  uint64_t majorantSegments = 0;    // segments handed out by majorant iterators
  uint64_t majorantViolations = 0;  // lookups whose sigma_t exceeded the majorant (must stay 0)

  // A deterministic measure of the time spent, for adaptive sampling's cost
  // per pixel: the lookups and segments dominate a sample's time; one unit
  // per path stands for the camera ray and the film.
  MMRTM_CPU_GPU uint64_t Work() const { return densityLookups + majorantSegments + paths; }

  MMRTM_CPU_GPU TraceCounters& operator+=(const TraceCounters& o) {
    paths += o.paths;
    densityLookups += o.densityLookups;
    realCollisions += o.realCollisions;
    nullCollisions += o.nullCollisions;
    shadowRays += o.shadowRays;
    majorantSegments += o.majorantSegments;
    majorantViolations += o.majorantViolations;
    return *this;
  }
};

}  // namespace mmrtm
