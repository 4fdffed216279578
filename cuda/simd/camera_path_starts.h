// The start of a batch of camera paths in SIMD lanes, a lane a pixel
// sample: its random numbers (PixelSampleRNG's PCG32 stream and the
// Owen-scrambled Sobol' pairs of the pixel position and of the free path),
// its camera ray (CameraView::GenerateRay, a pinhole), its end at the depth
// buffer, and the ray's interval in the tracked domain
// (SceneView::DomainInterval: the volume's box and the clip planes). Every
// operation is the scalar one's, in its order, so that every number is the
// scalar CameraSample's to the last bit (Testing/Cxx/TestSimdBackend fails
// on any drift, on every scene).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mmrtm/scene_view.h"

namespace mmrtm {

// A batch of pixel samples in structure-of-arrays form: the samples in,
// their starts out.
struct CameraPathStarts {
  std::vector<int32_t> x, y;          // the pixel
  std::vector<uint32_t> sampleIndex;  // in
  std::vector<uint64_t> rngState, rngInc, sobolKey;
  std::vector<uint32_t> sobolReversedIndex;         // PCG32::FromState, SobolPairs::FromKey
  std::vector<float> o[3], d[3], tMax;              // the camera ray (world) and its end
  std::vector<float> freePathU0, freePathU1;        // the free path's pair
  std::vector<float> indexO[3], indexD[3], t0, t1;  // the ray in index space, its interval in the domain
  std::vector<int32_t> inDomain;                    // 0 or 1
  std::vector<uint32_t> pairHashes;                 // the pairs' hashes, between the lanes' two passes

  // Room for n samples, and up to a vector's width more (the lanes' last
  // vector reads and writes whole vectors).
  void Resize(size_t n);
  size_t Size() const { return size_; }

 private:
  size_t size_ = 0;
};

// Whether the lanes start `s`'s camera paths: the Sobol' sampler, a pinhole
// (perspective or orthographic), a film of fewer than 2^31 pixels.
bool CameraPathStartsRun(const SceneView& s);

// Fills every output of samples [0, starts.Size()).
void StartCameraPaths(const SceneView& s, CameraPathStarts& starts);

}  // namespace mmrtm
