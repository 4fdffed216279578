#include "feature_pass.h"

#include <mutex>

#include "mmrtm/first_hit_features.h"
#include "parallel_for.h"

namespace mmrtm {

FeatureImages RenderFeatureImages(const SceneView& scene, int samplesPerPixel, int threads, TraceCounters* counters) {
  const int width = scene.camera.width, height = scene.camera.height;
  FeatureImages out;
  out.albedo = RGBImage{width, height, std::vector<RGB>((size_t)width * height)};
  out.normal = out.albedo;
  std::mutex counterMutex;
  // Rows in contiguous chunks: each pixel is written by one thread only.
  ParallelFor(height, threads, [&](int64_t y0, int64_t y1) {
    TraceCounters local;
    for (int y = (int)y0; y < (int)y1; ++y)
      for (int x = 0; x < width; ++x) {
        RGB albedo, normal;
        for (int i = 0; i < samplesPerPixel; ++i) {
          const FirstHitFeatures f = TraceFirstHitFeatures(scene, x, y, (uint32_t)i, local);
          albedo += f.albedo;
          normal += RGB(f.normal.x, f.normal.y, f.normal.z);
        }
        const size_t p = (size_t)y * width + x;
        out.albedo.pixels[p] = albedo / (float)samplesPerPixel;
        out.normal.pixels[p] = normal / (float)samplesPerPixel;
      }
    if (counters) {
      std::lock_guard<std::mutex> lock(counterMutex);
      *counters += local;
    }
  });
  return out;
}

}  // namespace mmrtm
