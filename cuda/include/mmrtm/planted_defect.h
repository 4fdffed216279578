// Planted defects: small deliberate bugs that prove the tests catch what
// they claim to (Testing/PlantedDefects, Documentation/accuracy.md).
//
// Compiled in only with -DMMRTM_PLANTED_DEFECTS=ON (a CPU-only build of its
// own); one at a time is switched on at run time by the environment
// variable MMRTM_PLANTED_DEFECT=<name>, so that one build serves every
// defect. In every other build Planted() is a constant false and the
// compiler removes the defect's code.
#pragma once

#include "mmrtm/defs.h"

#if defined(MMRTM_PLANTED_DEFECTS)
#if defined(__CUDACC__)
#error "MMRTM_PLANTED_DEFECTS is a CPU-only build (the defect is chosen by a host environment variable)"
#endif
#include <cstdio>
#include <cstdlib>
#include <cstring>
#endif

namespace mmrtm {

enum class Defect : uint8_t {
  None,
  VolumeAlbedo,       // the single-scattering albedo x0.97
  DiffuseLobe,        // the BSDF's diffuse lobe x0.95
  SpecularLobe,       // the BSDF's specular lobe x0.95
  PhaseSign,          // the Henyey-Greenstein g with its sign flipped
  MajorantLow,        // the refit's majorants x0.98 (not conservative)
  MinorantHigh,       // the refit's minorants x1.02 (not a lower bound)
  ShadowLastSegment,  // ratio tracking skips a shadow ray's last majorant segment
  LightWeights,       // next-event MIS weights that leave out the light choice (do not sum to one)
  EnvironmentPdf,     // the environment map's sampling pdf x1.05
  MapperColorRefit,   // the VTK mapper does not refit after a colour-function edit
  LabelSwap,          // label materials 1 and 2 swapped
  FilmVariance,       // the film's variance of the mean halved
  DenoiseVariance,    // Auto's estimate subtracts Var A + Var B (the halves' whole difference), not Var B
  // The VTK property's translation (VTKModule/Rendering/mmrtmVtkSceneTranslation.cxx), each rule 1 % off:
  VtkExtinction,         // sigma_t from scalar opacity per unit distance x1.01
  VtkColor,              // the colour (or grey) table x0.99
  VtkGradientOpacity,    // the gradient-opacity table x0.99
  VtkGradientMagnitude,  // the gradient-magnitude proxy x1.01 (cuda/host/derived_proxies.cpp)
  VtkComponentWeight,    // an independent component's colour x0.99 w^2
  VtkDependentRgb,       // dependent RGBA: the colour components divided by 1.01 x 255
  VtkLabelFunctions,     // a label's own scalar-opacity table x1.01 (sigma_t)
  VtkLabelMaterial,      // SetLabelMaterial's extinction x0.99
  VtkAmbient,            // the ambient environment's radiance x0.99
  VtkDiffuse,            // the lights' radiance (times Diffuse) x0.99
  VtkSpecularPower,      // the roughness from SpecularPower x1.01
  Count
};

// The names MMRTM_PLANTED_DEFECT takes, in Defect's order.
inline const char* DefectName(Defect d) {
  static const char* const names[] = {"none",
                                      "volume_albedo",
                                      "diffuse_lobe",
                                      "specular_lobe",
                                      "phase_sign",
                                      "majorant_low",
                                      "minorant_high",
                                      "shadow_last_segment",
                                      "light_weights",
                                      "environment_pdf",
                                      "mapper_color_refit",
                                      "label_swap",
                                      "film_variance",
                                      "denoise_variance",
                                      "vtk_extinction",
                                      "vtk_color",
                                      "vtk_gradient_opacity",
                                      "vtk_gradient_magnitude",
                                      "vtk_component_weight",
                                      "vtk_dependent_rgb",
                                      "vtk_label_functions",
                                      "vtk_label_material",
                                      "vtk_ambient",
                                      "vtk_diffuse",
                                      "vtk_specular_power"};
  static_assert(sizeof(names) / sizeof(names[0]) == (size_t)Defect::Count, "a name per defect");
  return names[(int)d];
}

#if defined(MMRTM_PLANTED_DEFECTS)
// The defect MMRTM_PLANTED_DEFECT names; an unknown name stops the program,
// so that a typo cannot pass as "caught by nothing, nothing to catch".
inline Defect ActiveDefect() {
  static const Defect active = [] {
    const char* name = std::getenv("MMRTM_PLANTED_DEFECT");
    if (!name || !*name) return Defect::None;
    for (int d = 0; d < (int)Defect::Count; ++d)
      if (std::strcmp(name, DefectName((Defect)d)) == 0) return (Defect)d;
    std::fprintf(stderr, "MMRTM_PLANTED_DEFECT=%s: no such planted defect\n", name);
    std::abort();
  }();
  return active;
}
inline bool Planted(Defect d) { return ActiveDefect() == d; }
#else
MMRTM_CPU_GPU constexpr bool Planted(Defect) { return false; }
#endif

}  // namespace mmrtm
