// VTK's projection blend modes (vtkVolumeMapper::SetBlendMode: maximum,
// minimum and average intensity, additive) as VTK's GPU ray caster computes
// them (vtkVolumeShaderComposer.h): the camera ray is sampled at a fixed
// step through the same lookups and clipping as the tracker, proxy 0's value
// is reduced along it, and the result is classified as the volume property
// says. No light and no randomness: one sample per pixel is the image.
//
// The film holds display values made linear (SRGBToLinear) so that the
// clamping display transform gives VTK's colours back.
#pragma once

#include "mmrtm/camera.h"
#include "mmrtm/counters.h"
#include "mmrtm/scene_view.h"
#include "mmrtm/tonemap.h"

namespace mmrtm {

// What a pixel of a projection shows, from the values of proxy 0 that its
// ray samples, each v normalized to [0, 1] over ProjectionSettings::valueRange
// as s, and a(v) the scalar opacity at v:
//   Maximum: the colour and opacity of the largest v (premultiplied);
//   Minimum: of the smallest v;
//   Average: grey, mean of a(v) * s over the samples with v in averageRange,
//            opaque (nothing where no sample counted);
//   Additive: grey, sum of a(v) * s (clamped to 1), opaque.
MMRTM_CPU_GPU inline PixelSample ProjectRay(const SceneView& s, const Ray& ray, float tMax, TraceCounters& ctr) {
  PixelSample out;
  const ProjectionSettings& p = s.settings.projection;
  Ray indexRay;
  float t0, t1;
  if (!s.DomainInterval(ray, tMax, &indexRay, &t0, &t1)) return out;
  const Classifier& classifier = s.classifier;
  const bool cropping = classifier.cropKeep != Classifier::kNoCropping;
  // The opacity the translation made the extinction from:
  // sigma_t = -ln(1 - a) / unit distance.
  auto opacity = [&](const Classification& c) { return 1.f - expf(-c.sigma_t * p.opacityUnitDistance); };
  const float span = p.valueRange[1] - p.valueRange[0];
  auto normalized = [&](float v) { return span > 0.f ? (v - p.valueRange[0]) / span : 0.f; };

  bool found = false;
  Classification extreme;  // the sample of the largest or least value
  float sum = 0.f;
  int counted = 0;
  const int steps = (int)ceilf((t1 - t0) / p.step);
  for (int k = 0; k < steps; ++k) {
    const float t = t0 + ((float)k + 0.5f) * p.step;
    if (t >= t1) break;
    const Vec3 world = ray(t);
    if (cropping && classifier.Cropped(world)) continue;
    // Every mode through Classify, whose proxy samples hold the value.
    const Classification c = classifier.Classify(world, indexRay(t));
    ++ctr.densityLookups;
    const float v = c.proxies.v[0];
    if (p.mode == IntensityProjection::Maximum || p.mode == IntensityProjection::Minimum) {
      const bool better = p.mode == IntensityProjection::Maximum ? v > extreme.proxies.v[0] : v < extreme.proxies.v[0];
      if (!found || better) {
        extreme = c;  // the other proxies (a label map, a gradient) as they are there
        found = true;
      }
      continue;
    }
    if (p.mode == IntensityProjection::Average && !(v >= p.averageRange[0] && v <= p.averageRange[1])) continue;
    sum += opacity(c) * normalized(v);
    ++counted;
  }

  if (p.mode == IntensityProjection::Maximum || p.mode == IntensityProjection::Minimum) {
    if (!found) return out;
    const float a = Clamp(opacity(extreme), 0.f, 1.f);
    if (!(a > 0.f)) return out;
    const RGB colour = classifier.Coefficients(extreme).albedo;
    out.L = RGB(SRGBToLinear(colour.r * a), SRGBToLinear(colour.g * a), SRGBToLinear(colour.b * a));
    out.alpha = a;
    return out;
  }
  if (counted == 0) return out;
  const float grey = SRGBToLinear(Clamp(p.mode == IntensityProjection::Average ? sum / (float)counted : sum, 0.f, 1.f));
  out.L = RGB(grey);
  out.alpha = 1.f;
  return out;
}

// Pixel (x, y) of a projection: the ray through its centre (one sample is
// the image). The backends call it per pixel in place of RenderPixelSample
// when the settings ask for a projection: the CPU backend from a
// translation unit of its own (cpu/cpu_projection.cpp), so that the path
// tracer's unit is compiled as without it (callgrind_binaries_ab.py: 1.000
// of the instructions on the five reference scenes). In that unit, it made
// the host compiler inline the path's lookups differently: 1.008-1.020 of
// the instructions dispatched per sample, up to 1.026 per pixel.
MMRTM_CPU_GPU inline PixelSample ProjectPixel(const SceneView& s, int x, int y, TraceCounters& ctr) {
  ++ctr.paths;
  const float tMax = s.cameraRayMaxDistance ? s.cameraRayMaxDistance[x + (int64_t)s.camera.width * y] : kInfinity;
  return ProjectRay(s, s.camera.GenerateRay((float)x + 0.5f, (float)y + 0.5f, 0.5f, 0.5f), tMax, ctr);
}

}  // namespace mmrtm
