// Instantiates the shared per-pixel integrator in a CUDA kernel. Compiling
// this file proves that every per-sample header is valid device code: a call
// to a host-only function from MMRTM_CPU_GPU code fails the build
// (--Werror cross-execution-space-call). The kernel is not launched here.
#include "mmrtm/film.h"
#include "mmrtm/integrator.h"
#include "mmrtm/tonemap.h"

namespace mmrtm {

__global__ void RenderPixelSamplesKernel(SceneView scene, FilmView film, uint32_t firstSample, int samples,
                                         TraceCounters* counters) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= film.width || y >= film.height) return;
  TraceCounters ctr;
  for (int i = 0; i < samples; ++i) {
    const uint32_t index = firstSample + (uint32_t)i;
    PixelSample ps = RenderPixelSample(scene, x, y, index, ctr);
    film.AddSample(x, y, ps.L, ps.alpha, index + 1);
  }
  atomicAdd((unsigned long long*)&counters->densityLookups, (unsigned long long)ctr.densityLookups);
}

__global__ void ToneMapKernel(FilmView film, float exposure, ToneMapper op, uint8_t* out) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= film.width || y >= film.height) return;
  const float* m = film.mean + 4 * ((int64_t)y * film.width + x);
  ToneMapPixel(RGB(m[0], m[1], m[2]), exposure, op, out + 3 * ((int64_t)y * film.width + x));
}

}  // namespace mmrtm
