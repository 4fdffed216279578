// Perspective and orthographic cameras, with an optional thin lens.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/ray.h"
#include "mmrtm/sampling.h"

namespace mmrtm {

enum class Projection : uint8_t { Perspective, Orthographic };

struct CameraView {
  Projection projection = Projection::Perspective;
  Vec3 position, forward, right, up;  // orthonormal; right = forward x up
  int width = 1, height = 1;
  float tanHalfFovY = 0.5f;     // perspective: tan of half the vertical field of view
  float orthoHalfHeight = 1.f;  // orthographic: half the view height in world units
  float lensRadius = 0.f;       // thin lens; 0 is a pinhole
  float focusDistance = 1.f;    // distance of the plane in focus along forward
  // The centre of the film in the view window, in units of half its width
  // and height (vtkCamera::WindowCenter): (0, 0) centres the film on the
  // view direction; a tile of a magnified screenshot sees its own part.
  float windowCenterX = 0.f, windowCenterY = 0.f;

  // Ray through film position (px, py) in pixels, y down; (u0, u1) on the lens.
  MMRTM_CPU_GPU Ray GenerateRay(float px, float py, float u0, float u1) const {
    float aspect = (float)width / (float)height;
    float sx = (2.f * px / width - 1.f + windowCenterX) * aspect;  // [-aspect, aspect] when centred
    float sy = 1.f - 2.f * py / height + windowCenterY;            // [-1, 1], up positive
    Ray ray;
    if (projection == Projection::Orthographic) {
      ray.o = position + right * (sx * orthoHalfHeight) + up * (sy * orthoHalfHeight);
      ray.d = forward;
    } else {
      ray.o = position;
      ray.d = Normalize(forward + right * (sx * tanHalfFovY) + up * (sy * tanHalfFovY));
    }
    if (lensRadius > 0.f) {
      float lx, ly;
      SampleUniformDiskConcentric(u0, u1, &lx, &ly);
      Vec3 lens = right * (lx * lensRadius) + up * (ly * lensRadius);
      float ft = focusDistance / Dot(ray.d, forward);
      Vec3 focus = ray(ft);
      ray.o = ray.o + lens;
      ray.d = Normalize(focus - ray.o);
    }
    return ray;
  }
};

}  // namespace mmrtm
