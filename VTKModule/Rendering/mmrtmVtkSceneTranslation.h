// PRIVATE to MMRTM::Rendering: VTK's description of a volume rendering
// (vtkVolumeProperty, vtkCamera, vtkLight) translated into the tracer's
// Scene. The rules, which Documentation/vtk-mapper.md states for users:
//
// - Scalar opacity alpha(x) per ScalarOpacityUnitDistance d becomes the
//   extinction sigma_t(x) = -ln(1 - alpha(x)) / d, so that a slab of
//   thickness d lets 1 - alpha through, as in VTK's compositing.
// - Dependent components (IndependentComponents off), as VTK: 2 components
//   are colour (through the colour function) and opacity (through the
//   scalar-opacity function); 4 are RGB (the albedo itself, unsigned char
//   scaled to 0-1) and opacity. The RGB albedo is the product of three
//   3-channel CCTFs, one per component proxy, each scaling one channel: the
//   merge rule "coefficients from several proxies multiply".
// - Independent components (IndependentComponents on, 2 to 4 components):
//   each component is a material over its own proxy with its own functions,
//   its albedo times the square of the component weight (VTK's GPU mapper
//   scales an opaque component's colour so; weight 0 removes it), and the
//   materials are mixed additively (extinctions add, colours weighted by
//   extinction), as VTK mixes independent components.
// - Colour becomes the albedo; gradient opacity g(|grad x|) multiplies
//   sigma_t through a gradient-magnitude proxy (made only when used).
// - The functions are sampled at kTableSize points over the scalar range, as
//   VTK's own GPU mapper samples them into tables, which keeps midpoints,
//   sharpness and log scales.
// - Shade off, as VTK's mappers: the colour glows unlit (emission sigma_t *
//   colour, albedo 0: emission and absorption, VTK's compositing); with
//   TranslationOptions::unshadedScatters the colour is instead the albedo
//   of volume scattering (isotropic phase), lit by the lights. Shade on:
//   surface scattering with probability kShadedSurfaceProbability on the
//   gradient normal (1 with TranslationOptions::localLighting, as VTK
//   shades every sample on its gradient); roughness (2 / (SpecularPower + 2))^(1/4) (the
//   Blinn-Phong exponent's GGX equivalent), 1 when Specular is 0. Ambient is
//   a constant environment light of that radiance.
// - Lights: a directional light (scene light, headlight, camera light)
//   gives irradiance pi * intensity * colour * Diffuse, so that a white
//   Lambertian surface facing it shows intensity * colour * Diffuse, as
//   VTK's diffuse shading does; a positional light gives the same
//   irradiance at its focal point.
// - Blend mode ISOSURFACE: surfaces where the scalars cross the property's
//   iso-values (TranslationOptions::isoValues), each crossing as opaque as
//   a slab isoSampleDistance thick at the iso-value's opacity (an optical
//   depth -ln(1 - alpha) * isoSampleDistance / d across it, as VTK's GPU
//   mapper composites one sample per crossing): extinction only in a band
//   of half-width kIsoBandFraction
//   of the scalar range around each iso-value, proportional to the
//   gradient magnitude there (so that a ray crossing the band along the
//   normal meets that optical depth, whatever the gradient), with surface
//   probability 1 when shaded.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "label_materials.h"
#include "scene.h"

class vtkCamera;
class vtkDataArray;
class vtkImageData;
class vtkRenderer;
class vtkVolumeProperty;

namespace mmrtm
{

constexpr int kTableSize = 256;
constexpr float kShadedSurfaceProbability = 0.8f;
constexpr float kIsoBandFraction = 1.f / 512.f;

// What the mapper adds to the property's description.
struct TranslationOptions
{
  bool unshadedScatters = false; // Shade off scatters the lights (else it glows, as VTK)
  bool localLighting = false;    // VTK's local lighting: Shade on is a surface at every point
  bool isosurface = false;       // ISOSURFACE blend: surfaces at isoValues only
  std::vector<double> isoValues;
  float isoSampleDistance = 1.f; // a crossing is as opaque as this length at the iso-value's opacity
  bool operator==(const TranslationOptions& o) const
  {
    return unshadedScatters == o.unshadedScatters && localLighting == o.localLighting && isosurface == o.isosurface &&
      isoValues == o.isoValues && isoSampleDistance == o.isoSampleDistance;
  }
};

// Whether component `component`'s gradient opacity is in use (enabled and
// not constant 1), so that the gradient-magnitude proxy is needed.
bool UsesGradientOpacity(vtkVolumeProperty* property, int component);
// Whether the component or, with labels, any label uses gradient opacity.
bool NeedsGradientProxy(vtkVolumeProperty* property, int component, bool labels);

// Which proxies the translation may read (index in Scene::proxies, or -1).
struct ProxyLayout
{
  std::array<float, 2> scalarRange{ 0.f, 0.f };
  int gradient = -1; // gradient magnitude of the scalars
  std::array<float, 2> gradientRange{ 0.f, 0.f };
  int labels = -1;     // a label map (the mapper's mask, LABELMAP)
  int binaryMask = -1; // a binary mask (BINARY)
  // IndependentComponents off: with 2 components, proxy 0 is coloured by
  // the colour function and `opacity` (component 1) gives the opacity; with
  // 4, `rgb` are the colour components (divided by colorScale) and `opacity`
  // (component 3) goes through the scalar-opacity function.
  int opacity = -1;
  std::array<float, 2> opacityRange{ 0.f, 0.f };
  int rgb[3] = { -1, -1, -1 };
  float colorScale = 255.f;
  // IndependentComponents on with several components: proxy c is
  // component c (c < independent), each with its own functions, mixed
  // additively (Classifier::additive).
  int independent = 0;
  std::array<std::array<float, 2>, 4> componentRanges{};
  // The gradient magnitude of an independent component whose gradient
  // opacity is used (-1: none), while there is room among the 4 proxies.
  std::array<int, 4> componentGradient{ -1, -1, -1, -1 };
  std::array<std::array<float, 2>, 4> componentGradientRanges{};
};

// The proxies of an input as the property uses them, in place of
// scene.proxies (as vtkVolumeInputHelper prepares VTK's textures): the
// input's component 0 as "scalars"; with `dependent` 2 or 4 (dependent
// components) the opacity and colour components, with `independent` 2 to 4
// each component and, while there is room, the gradient magnitude of each
// one with gradient opacity; the gradient magnitude of the shaded or
// opacity component when `needGradient`; and the mask (a label map when
// `labels`, else binary) put on the input's grid by nearest neighbour.
// Returns where each went. `warn` says what was left out. Throws
// InputError when the combination needs more than kMaxProxies.
ProxyLayout BuildProxies(vtkVolumeProperty* property, vtkImageData* input, vtkDataArray* scalars, vtkImageData* mask,
  int dependent, int independent, bool needGradient, bool labels, Scene& scene,
  const std::function<void(const std::string&)>& warn);

// Replaces the scene's TFs, materials and selectors with those of the
// property's component `component`: one material from its functions (the
// default material), and with a label map one material per label that has
// functions of its own, chosen by an MDPTF over the labels. As in VTK's GPU
// mapper, such a label is classified by its own functions alone (a function
// it lacks is the component's): where its opacity is 0 it is empty, the
// component's functions do not show through (the default material is gated
// off those labels). Label 0 and labels without functions take the
// component's functions.
// Values that are not finite are read as 0: a NaN node value of a transfer
// function is 0 at its node (its neighbours still ramp to it; a node at a
// NaN position is dropped), any other NaN reaching the scene (a component
// weight) is 0; returns how many there were, for the caller to warn about.
// (A NaN unit distance is VTK's default 1, without a warning.)
// With isosurface options and no gradient proxy in the layout, or with
// several components, the iso-values are not used (the caller warns).
int SetMaterialsFromProperty(vtkVolumeProperty* property, int component, const ProxyLayout& proxies,
  const TranslationOptions& options, Scene& scene);

// Whether some material of the scene scatters light (an albedo above 0);
// a scene whose materials only glow needs no light and no bounce.
bool AnyMaterialScatters(const Scene& scene);

// Gives label `label` the material of `look` by the one label rule
// (LabelMaterial: density and albedo), shaded as the property's component
// `component` is, without gradient opacity: in place of the material that
// the property's label functions made, else added to the label selector.
// Where the look's density is 0 (hidden) the property's component
// functions show, as for a label without a look.
// Throws InputError for a look out of range.
void SetLabelLook(int label, const LabelLook& look, vtkVolumeProperty* property, int component,
  const ProxyLayout& proxies, const TranslationOptions& options, Scene& scene);

// Gives label `label`'s material (made by SetMaterialsFromProperty) the
// surface and phase parameters VTK's label functions cannot say: a JSON
// object with any of "roughness", "metallic", "surface_probability" (0..1),
// "anisotropy" (-1..1) and "emission" ([r, g, b] >= 0). Its colour, opacity
// and gradient opacity stay the property's. Throws InputError naming the
// key for an unknown key or a value out of range; a label without a
// material of its own (no function in the property) is left alone.
void SetLabelMaterialParameters(int label, const std::string& json, Scene& scene);

// Sets the scene's camera from VTK's.
void SetCameraFromVtk(vtkCamera* camera, Scene& scene);

// Replaces the scene's lights with the renderer's lights that are on, and
// the environment with the property's ambient term.
void SetLightsFromVtk(vtkRenderer* renderer, vtkVolumeProperty* property, Scene& scene);

} // namespace mmrtm
