// The extinction of a plain scene at many points at once, in SIMD lanes: the
// densest stage of a CPU sample (Documentation/performance.md: 7.9 density
// lookups a sample), the first stage of the SIMD tracer (issue 34).
//
// A plain scene (Classifier::plain) has one proxy, one material and one
// density TF; its extinction at a point of proxy 0's index space is what
// Classifier::Classify returns there: a trilinear (or, for a label map,
// nearest) lookup in the native voxel type, the density TF, the material's
// base density and the extinction clamp. PlainExtinctionSimd computes the
// same bits through the same per-lane templates (mmrtm/volume.h,
// transfer_function.h, classifier.h) instantiated for Highway vectors, on
// the best instruction set of the machine (runtime dispatch; simd_targets.h
// forces another for tests).
#pragma once

#include <cstddef>

#include "mmrtm/classifier.h"

namespace mmrtm {

// sigma_t[i] = the extinction at index point (x[i], y[i], z[i]) of proxy 0,
// for i < count; `classifier` must be plain. A CCTF density TF runs in
// lanes; another TF type, or a volume of 2 GiB or more (whose byte offsets
// do not fit the gathers' 32 bits), one lane at a time.
void PlainExtinctionSimd(const Classifier& classifier, const float* x, const float* y, const float* z, size_t count,
                         float* sigma_t);

// The same through Classifier::Classify, one point at a time: the reference.
void PlainExtinctionScalar(const Classifier& classifier, const float* x, const float* y, const float* z, size_t count,
                           float* sigma_t);

// The Highway target that PlainExtinctionSimd runs on now ("AVX3", "AVX2", ...),
// and its floats a vector (16, 8, ...).
const char* PlainExtinctionTarget();
int PlainExtinctionLaneCount();

}  // namespace mmrtm
