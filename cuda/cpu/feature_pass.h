// The denoised preview's auxiliary images (mmrtm/first_hit_features.h),
// rendered on the CPU whatever backend renders the radiance: a pass that
// traces camera rays to their first collision only, a small part of a
// sample's cost. Host-only.
#pragma once

#include <vector>

#include "image_io.h"
#include "mmrtm/counters.h"
#include "mmrtm/scene_view.h"

namespace mmrtm {

struct FeatureImages {
  RGBImage albedo;  // mean first-hit albedo per pixel, row 0 at the top
  RGBImage normal;  // mean first-hit normal per pixel (x, y, z as r, g, b)
};

// `samplesPerPixel` feature samples per pixel (indices 0 ..), on `threads`
// threads (0: all). The same images at any thread count.
FeatureImages RenderFeatureImages(const SceneView& scene, int samplesPerPixel, int threads,
                                  TraceCounters* counters = nullptr);

}  // namespace mmrtm
