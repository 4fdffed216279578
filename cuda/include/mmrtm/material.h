// Materials and their coefficients (paper sections 3 and 5).
//
// A material is a set of base coefficients; each coefficient may be
// multiplied by coefficient TFs (CCTF, CPCTF, CDPTF) over any proxy. Several
// TFs on one coefficient multiply, as VTK does for multi-dimensional TFs.
#pragma once

#include "mmrtm/defs.h"
#include "mmrtm/vecmath.h"

namespace mmrtm {

// The coefficients a TF can drive, and where each lives in the flat array.
enum class Quantity : uint8_t {
  Density,             // extinction sigma_t per world unit (mm) at TF value 1
  Albedo,              // single-scattering albedo, RGB; also the surface base colour
  Roughness,           // perceptual roughness in [0, 1]; GGX alpha = roughness^2
  Metallic,            // 0 dielectric .. 1 metal (specular colour = albedo)
  SurfaceProbability,  // P_fs: probability that a real collision scatters on the surface BSDF
  Emission,            // emitted radiance, RGB (the source term is sigma_t * emission)
  Anisotropy,          // Henyey-Greenstein g in (-1, 1)
  Count
};
constexpr int kQuantityCount = (int)Quantity::Count;
constexpr int kCoefficientFloats = 11;

MMRTM_CPU_GPU inline int QuantityOffset(Quantity q) {
  const int offsets[kQuantityCount] = {0, 1, 4, 5, 6, 7, 10};
  return offsets[(int)q];
}
MMRTM_CPU_GPU inline int QuantityChannels(Quantity q) {
  return (q == Quantity::Albedo || q == Quantity::Emission) ? 3 : 1;
}

// One coefficient TF attached to a material quantity.
struct CoefficientBinding {
  int tf = 0;
  Quantity quantity = Quantity::Density;
  uint8_t padding[3] = {};  // explicit: equal bindings have equal bytes (scene_uploads.h)
};

struct MaterialView {
  float base[kCoefficientFloats] = {};
  // Bindings [bindingBegin, bindingBegin + bindingCount) of the scene's
  // binding array, the density ones first (densityBindingCount of them), so
  // that the per-lookup density evaluation touches only those.
  int bindingBegin = 0;
  int densityBindingCount = 0;
  int bindingCount = 0;
};

// Coefficients at a point, after the TFs.
struct MaterialCoefficients {
  float sigma_t = 0.f;
  RGB albedo;
  float roughness = 1.f;
  float metallic = 0.f;
  float surfaceProbability = 0.f;
  RGB emission;
  float g = 0.f;
};

}  // namespace mmrtm
