// The mapper's refit after an edit, against a mapper built after it.
//
// For each kind of edit of a vtkVolumeProperty (its functions edited in
// place, as an application's transfer-function editor does, or its
// settings), of the label functions and label materials, and of the
// mapper's own settings, two mappers render the same scene with one seed
// and sample count:
//   A: built and rendered before the edit, edited, rendered again (so it
//      must notice the edit and redo exactly what the edit invalidates);
//   B: a fresh mapper given the edited property from the start.
// A's accumulated film (GetAccumulatedImage: linear RGB and coverage) must
// equal B's to the bit: stale translation state in A (a function not read
// again, a proxy not rebuilt, a material left over) cannot hide behind the
// noise. Each edit must also change A's image (the edit is not a no-op),
// except the few the mapper documents as not used (the interpolation
// type) or as applied after the film (the exposure, the tone mapping). And A
// must do the work its kind of edit needs and no more (Work: counted by the
// mapper's scene builds, translations, restarts, and the majorant grid's
// builds and refits): the exposure and an unchanged render none, a camera
// or settings edit a restart without a refit, a colour or shading edit a
// translation without a refit (the majorants bound extinction only), an
// opacity edit a translation and a refit.
//
//   TestMapperEdits [-D DATA_DIR] [CASE...]     (no CASE: all of them)
//
// C++ rather than Python so that the planted-defect build (no wrapping) runs
// it: with MMRTM_PLANTED_DEFECT=mapper_color_refit the mapper misses
// colour-function edits, and the colour cases fail here.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkContourValues.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkImageShrink3D.h>
#include <vtkNew.h>
#include <vtkNrrdReader.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPlane.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTexture.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

#include "vtkMultiMaterialProperty.h"
#include "vtkMultiMaterialVolumeMapper.h"

namespace
{
constexpr int kSize = 64;   // the window: small, the test is about state, not pixels
constexpr int kSamples = 4; // per pixel, one render
constexpr int kSeed = 7;

// The objects a case sets up and edits. Each mapper gets its own property
// and functions (made by the case's setup), so A's edits cannot reach B.
struct Objects
{
  vtkVolumeProperty* property;
  vtkMultiMaterialVolumeMapper* mapper;
  vtkPiecewiseFunction* opacity;
  vtkColorTransferFunction* color;
  vtkTexture* environment; // the environment texture of the case's mapper
  vtkPlane* plane;         // a clipping plane of the case's mapper
};

enum class Input
{
  Head,         // ct_head_headsq.nrrd, every other voxel: 32 x 32 x 47 int16
  HeadLabels,   // the same with a label map (labels 1 and 2) as the mask
  TwoComponents // 32^3, 2 unsigned char components
};

// The work an edit must cause in the mapper, and no more.
enum class Work
{
  Display,     // none: the accumulation goes on (the exposure, no change at all)
  Restart,     // the accumulation restarts; nothing translated, no refit
  Translate,   // the property translated again; the majorants kept (what changed is not extinction)
  Refit,       // the property translated again and the majorants refitted (extinction changed)
  Rebuild,     // the proxies and the grid's summaries built again
  Accelerator, // a restart; the grid built or refitted for the new accelerator
};

struct Case
{
  std::string name;
  Input input;
  std::function<void(Objects&)> setup, edit;
  bool changesImage = true; // false: documented as not used by the film
  Work work = Work::Refit;
};

// The mapper's counters of work done.
struct Counts
{
  int builds, translations, restarts, gridBuilds, gridRefits;
};

Counts CountsOf(vtkMultiMaterialVolumeMapper* m)
{
  return { m->GetNumberOfSceneBuilds(), m->GetNumberOfRefits(), m->GetNumberOfRestarts(),
    m->GetNumberOfMajorantGridBuilds(), m->GetNumberOfMajorantGridRefits() };
}

// Whether the work done (`d`, counts after the edit less before) is what
// `w` allows.
bool WorkAsExpected(Work w, const Counts& d)
{
  switch (w)
  {
    case Work::Display:
      return d.builds == 0 && d.translations == 0 && d.restarts == 0 && d.gridBuilds == 0 && d.gridRefits == 0;
    case Work::Restart:
      return d.builds == 0 && d.translations == 0 && d.restarts == 1 && d.gridBuilds == 0 && d.gridRefits == 0;
    case Work::Translate:
      return d.builds == 0 && d.translations == 1 && d.restarts == 1 && d.gridBuilds == 0 && d.gridRefits == 0;
    case Work::Refit:
      return d.builds == 0 && d.translations == 1 && d.restarts == 1 && d.gridBuilds == 0 && d.gridRefits == 1;
    case Work::Rebuild:
      return d.builds == 1 && d.translations == 1 && d.restarts == 1 && d.gridBuilds == 1 && d.gridRefits == 1;
    case Work::Accelerator:
      return d.builds == 0 && d.translations == 0 && d.restarts == 1 && d.gridBuilds <= 1 && d.gridRefits <= 1;
  }
  return false;
}

const char* WorkName(Work w)
{
  switch (w)
  {
    case Work::Display:
      return "display only";
    case Work::Restart:
      return "a restart";
    case Work::Translate:
      return "a translation and restart";
    case Work::Refit:
      return "a translation, refit and restart";
    case Work::Rebuild:
      return "a rebuild";
    case Work::Accelerator:
      return "a restart for the accelerator";
  }
  return "?";
}

// A ball of value `peak` at `centre` (voxel units) falling off to 0 at `radius`.
double Ball(const int ijk[3], const double centre[3], double radius, double peak)
{
  double r2 = 0;
  for (int a = 0; a < 3; ++a)
    r2 += (ijk[a] - centre[a]) * (ijk[a] - centre[a]);
  return std::max(0.0, peak * (1.0 - std::sqrt(r2) / radius));
}

// 32^3, component 0 a ball on one side, component 1 a ball on the other.
vtkSmartPointer<vtkImageData> TwoComponentVolume()
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(32, 32, 32);
  image->SetSpacing(1, 1, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 2);
  auto* p = static_cast<unsigned char*>(image->GetScalarPointer());
  const double c0[3] = { 12, 16, 16 }, c1[3] = { 20, 14, 17 };
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i, p += 2)
      {
        const int ijk[3] = { i, j, k };
        p[0] = static_cast<unsigned char>(Ball(ijk, c0, 11, 255));
        p[1] = static_cast<unsigned char>(Ball(ijk, c1, 11, 255));
      }
  return image;
}

// Labels 1 and 2 (two balls) on the head's grid.
vtkSmartPointer<vtkImageData> HeadLabels(vtkImageData* head)
{
  auto labels = vtkSmartPointer<vtkImageData>::New();
  labels->CopyStructure(head);
  labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  int dims[3];
  head->GetDimensions(dims);
  auto* p = static_cast<unsigned char*>(labels->GetScalarPointer());
  const double c1[3] = { 0.35 * dims[0], 0.5 * dims[1], 0.5 * dims[2] };
  const double c2[3] = { 0.65 * dims[0], 0.45 * dims[1], 0.4 * dims[2] };
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i)
      {
        const int ijk[3] = { i, j, k };
        *p++ = Ball(ijk, c1, 0.28 * dims[0], 1) > 0 ? 1 : Ball(ijk, c2, 0.23 * dims[0], 1) > 0 ? 2 : 0;
      }
  return labels;
}

// A small equirectangular sky: brighter toward the top.
vtkSmartPointer<vtkTexture> EnvironmentTexture()
{
  vtkNew<vtkImageData> sky;
  sky->SetDimensions(8, 4, 1);
  sky->AllocateScalars(VTK_FLOAT, 3);
  auto* p = static_cast<float*>(sky->GetScalarPointer());
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x, p += 3)
    {
      p[0] = 0.2f + 0.2f * y;
      p[1] = 0.3f + 0.2f * y;
      p[2] = 0.5f + 0.3f * y;
    }
  auto texture = vtkSmartPointer<vtkTexture>::New();
  texture->SetInputData(sky);
  return texture;
}

// Head CT values run 0..3926: soft tissue faintly, bone more.
void HeadFunctions(Objects& o)
{
  o.opacity->AddPoint(500, 0.0);
  o.opacity->AddPoint(900, 0.05);
  o.opacity->AddPoint(1300, 0.4);
  o.opacity->AddPoint(2500, 0.9);
  o.color->AddRGBPoint(500, 0.8, 0.5, 0.4);
  o.color->AddRGBPoint(1300, 0.95, 0.9, 0.8);
  o.color->AddRGBPoint(2500, 1.0, 1.0, 0.95);
  o.property->SetScalarOpacity(o.opacity);
  o.property->SetColor(o.color);
  o.property->SetAmbient(0.2);
}

void Shaded(Objects& o)
{
  HeadFunctions(o);
  o.property->ShadeOn();
}

// Labels 1 and 2 with functions of their own (solid red, translucent blue);
// label 2 only when `both`.
void Labelled(Objects& o, bool both = true)
{
  HeadFunctions(o);
  vtkNew<vtkPiecewiseFunction> solid, faint;
  solid->AddPoint(0, 0.6);
  solid->AddPoint(4000, 0.6);
  faint->AddPoint(0, 0.1);
  faint->AddPoint(4000, 0.3);
  vtkNew<vtkColorTransferFunction> red, blue;
  red->AddRGBPoint(0, 0.9, 0.15, 0.1);
  blue->AddRGBPoint(0, 0.2, 0.3, 0.9);
  blue->AddRGBPoint(4000, 0.5, 0.6, 1.0);
  o.property->SetLabelScalarOpacity(1, solid);
  o.property->SetLabelColor(1, red);
  if (!both)
    return;
  o.property->SetLabelScalarOpacity(2, faint);
  o.property->SetLabelColor(2, blue);
}

// Component 0 orange, component 1 blue, each over 0..255.
void TwoComponentFunctions(Objects& o)
{
  o.opacity->AddPoint(20, 0.0);
  o.opacity->AddPoint(255, 0.5);
  o.color->AddRGBPoint(0, 1.0, 0.6, 0.2);
  o.color->AddRGBPoint(255, 1.0, 0.8, 0.5);
  o.property->SetScalarOpacity(0, o.opacity);
  o.property->SetColor(0, o.color);
  vtkNew<vtkPiecewiseFunction> opacity1;
  opacity1->AddPoint(20, 0.0);
  opacity1->AddPoint(255, 0.3);
  vtkNew<vtkColorTransferFunction> color1;
  color1->AddRGBPoint(0, 0.2, 0.4, 1.0);
  color1->AddRGBPoint(255, 0.6, 0.8, 1.0);
  o.property->SetScalarOpacity(1, opacity1);
  o.property->SetColor(1, color1);
}

vtkPiecewiseFunction* Ramp(vtkPiecewiseFunction* f, double x0, double x1)
{
  f->RemoveAllPoints();
  f->AddPoint(x0, 0.0);
  f->AddPoint(x1, 1.0);
  return f;
}

std::vector<Case> Cases()
{
  std::vector<Case> c;
  // vtkVolumeProperty: its functions, edited in place.
  c.push_back(
    { "scalar-opacity-point", Input::Head, HeadFunctions, [](Objects& o) { o.opacity->AddPoint(1100, 0.8); } });
  c.push_back({ "scalar-opacity-replaced", Input::Head, HeadFunctions,
    [](Objects& o)
    {
      vtkNew<vtkPiecewiseFunction> f;
      o.property->SetScalarOpacity(Ramp(f, 1000, 3000));
    } });
  c.push_back(
    { "unit-distance", Input::Head, HeadFunctions, [](Objects& o) { o.property->SetScalarOpacityUnitDistance(3.0); } });
  c.push_back(
    { "color-rgb-point", Input::Head, HeadFunctions, [](Objects& o) { o.color->AddRGBPoint(1300, 0.2, 0.5, 0.9); } });
  c.push_back({ "color-rgb-to-gray", Input::Head, HeadFunctions,
    [](Objects& o)
    {
      vtkNew<vtkPiecewiseFunction> gray;
      gray->AddPoint(500, 0.3);
      gray->AddPoint(2500, 0.9);
      o.property->SetColor(gray);
    } });
  c.push_back({ "color-gray-point", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      vtkNew<vtkPiecewiseFunction> gray;
      gray->AddPoint(500, 0.3);
      gray->AddPoint(2500, 0.9);
      o.property->SetColor(gray);
    },
    [](Objects& o) { o.property->GetGrayTransferFunction()->AddPoint(1300, 0.1); } });
  c.push_back({ "gradient-opacity-enabled", Input::Head, HeadFunctions,
    [](Objects& o) { Ramp(o.property->GetGradientOpacity(), 0, 300); } });
  c.push_back({ "gradient-opacity-point", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      vtkNew<vtkPiecewiseFunction> g;
      o.property->SetGradientOpacity(Ramp(g, 0, 300));
    },
    [](Objects& o) { o.property->GetGradientOpacity()->AddPoint(100, 0.9); } });
  c.push_back({ "gradient-opacity-disabled", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      vtkNew<vtkPiecewiseFunction> g;
      o.property->SetGradientOpacity(Ramp(g, 0, 300));
    },
    [](Objects& o) { o.property->DisableGradientOpacityOn(); } });
  c.push_back({ "shade-on", Input::Head, HeadFunctions, [](Objects& o) { o.property->ShadeOn(); } });
  c.push_back({ "shade-off", Input::Head, Shaded, [](Objects& o) { o.property->ShadeOff(); } });
  c.push_back({ "ambient", Input::Head, Shaded, [](Objects& o) { o.property->SetAmbient(0.8); } });
  c.push_back({ "diffuse", Input::Head, Shaded, [](Objects& o) { o.property->SetDiffuse(0.2); } });
  c.push_back({ "specular", Input::Head, Shaded, [](Objects& o) { o.property->SetSpecular(0.0); } });
  c.push_back({ "specular-power", Input::Head, Shaded, [](Objects& o) { o.property->SetSpecularPower(60); } });
  c.push_back({ "interpolation-nearest", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      o.property->SetInterpolationTypeToLinear(); // VTK's default is nearest
    },
    [](Objects& o) { o.property->SetInterpolationTypeToNearest(); }, false });
  c.push_back({ "transfer-function-2d", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      vtkNew<vtkImageData> table; // x: scalar value, y: gradient magnitude
      table->SetDimensions(16, 8, 1);
      table->SetOrigin(0, 0, 0);
      table->SetSpacing(4000.0 / 15, 600.0 / 7, 1);
      table->AllocateScalars(VTK_FLOAT, 4);
      auto* p = static_cast<float*>(table->GetScalarPointer());
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x, p += 4)
        {
          p[0] = 0.9f;
          p[1] = 0.3f + 0.04f * x;
          p[2] = 0.2f + 0.1f * y;
          p[3] = x >= 5 ? 0.1f + 0.05f * y : 0.f;
        }
      o.property->SetTransferFunction2D(table);
      o.property->SetTransferFunctionMode(vtkVolumeProperty::TF_2D);
    },
    [](Objects& o)
    {
      vtkImageData* table = o.property->GetTransferFunction2D();
      auto* p = static_cast<float*>(table->GetScalarPointer());
      for (int i = 0; i < 16 * 8; ++i)
        p[4 * i + 1] *= 0.5f;
      table->Modified();
    } });

  // Components.
  c.push_back({ "independent-components-off", Input::TwoComponents, TwoComponentFunctions,
    [](Objects& o) { o.property->IndependentComponentsOff(); } });
  c.push_back({ "independent-components-on", Input::TwoComponents,
    [](Objects& o)
    {
      TwoComponentFunctions(o);
      o.property->IndependentComponentsOff();
    },
    [](Objects& o) { o.property->IndependentComponentsOn(); } });
  c.push_back({ "component-weight", Input::TwoComponents, TwoComponentFunctions,
    [](Objects& o) { o.property->SetComponentWeight(1, 0.3); } });
  c.push_back({ "component-color-point", Input::TwoComponents, TwoComponentFunctions,
    [](Objects& o) { o.property->GetRGBTransferFunction(1)->AddRGBPoint(128, 0.1, 1.0, 0.1); } });
  c.push_back({ "component-opacity-point", Input::TwoComponents, TwoComponentFunctions,
    [](Objects& o) { o.property->GetScalarOpacity(1)->AddPoint(128, 0.9); } });
  c.push_back({ "component-gradient-opacity", Input::TwoComponents, TwoComponentFunctions,
    [](Objects& o) { Ramp(o.property->GetGradientOpacity(1), 0, 40); } });

  // A label map (the mask): per-label functions and materials.
  const auto labelled = [](Objects& o) { Labelled(o); };
  c.push_back({ "label-opacity-point", Input::HeadLabels, labelled,
    [](Objects& o) { o.property->GetLabelScalarOpacity(1)->AddPoint(1000, 0.05); } });
  c.push_back({ "label-color-point", Input::HeadLabels, labelled,
    [](Objects& o) { o.property->GetLabelColor(2)->AddRGBPoint(1000, 0.1, 0.9, 0.1); } });
  c.push_back({ "label-color-replaced", Input::HeadLabels, labelled,
    [](Objects& o)
    {
      vtkNew<vtkColorTransferFunction> green;
      green->AddRGBPoint(0, 0.1, 0.8, 0.2);
      o.property->SetLabelColor(1, green);
    } });
  c.push_back({ "label-gradient-opacity", Input::HeadLabels, labelled,
    [](Objects& o)
    {
      vtkNew<vtkPiecewiseFunction> g;
      o.property->SetLabelGradientOpacity(2, Ramp(g, 0, 200));
    } });
  c.push_back({ "label-added", Input::HeadLabels, [](Objects& o) { Labelled(o, false); },
    [](Objects& o)
    {
      vtkNew<vtkColorTransferFunction> yellow;
      yellow->AddRGBPoint(0, 0.9, 0.9, 0.1);
      o.property->SetLabelColor(2, yellow);
    } });
  // Shaded: a glowing (unshaded) label has no surface to give parameters to.
  c.push_back({ "label-material", Input::HeadLabels,
    [&](Objects& o)
    {
      labelled(o);
      o.property->ShadeOn();
    },
    [](Objects& o)
    { o.mapper->SetLabelMaterialParameters(1, R"({"roughness": 0.2, "metallic": 1, "surface_probability": 1})"); } });
  c.push_back({ "label-material-edited", Input::HeadLabels,
    [](Objects& o)
    {
      Labelled(o);
      o.mapper->SetLabelMaterialParameters(1, R"({"roughness": 0.2, "surface_probability": 1})");
    },
    [](Objects& o) { o.mapper->SetLabelMaterialParameters(1, R"({"emission": [2, 0, 0]})"); } });
  c.push_back({ "label-material-removed", Input::HeadLabels,
    [](Objects& o)
    {
      Labelled(o);
      o.mapper->SetLabelMaterialParameters(2, R"({"anisotropy": 0.8, "emission": [0, 0, 3]})");
    },
    [](Objects& o) { o.mapper->RemoveAllLabelMaterialParameters(); } });
  c.push_back({ "mask-binary", Input::HeadLabels, labelled, [](Objects& o) { o.mapper->SetMaskTypeToBinary(); } });
  // Labels by the one label rule (SetLabelMaterial: how Slicer's segments come).
  const auto looks = [](Objects& o)
  {
    Labelled(o, false);
    o.mapper->SetLabelMaterial(1, 0.9, 0.2, 0.1, 0.6);
  };
  c.push_back({ "label-look-added", Input::HeadLabels, looks,
    [](Objects& o) { o.mapper->SetLabelMaterial(2, 0.1, 0.3, 0.9, 1.0); } });
  c.push_back({ "label-look-colour", Input::HeadLabels, looks,
    [](Objects& o) { o.mapper->SetLabelMaterial(1, 0.1, 0.9, 0.2, 0.6); } });
  c.push_back({ "label-look-opacity", Input::HeadLabels, looks,
    [](Objects& o) { o.mapper->SetLabelMaterial(1, 0.9, 0.2, 0.1, 0.2); } });
  c.push_back({ "label-look-over-functions", Input::HeadLabels, labelled,
    [](Objects& o) { o.mapper->SetLabelMaterial(2, 0.9, 0.9, 0.1, 1.0); } });
  c.push_back({ "label-look-removed", Input::HeadLabels, looks, [](Objects& o) { o.mapper->RemoveLabelMaterial(1); } });
  c.push_back({ "label-look-same-values", Input::HeadLabels, looks,
    [](Objects& o) { o.mapper->SetLabelMaterial(1, 0.9, 0.2, 0.1, 0.6); }, false, Work::Display });
  // A front end that sets all its labels at each update (ParaView's
  // representation): removed and set again as they were, no change.
  c.push_back({ "label-looks-set-again", Input::HeadLabels, looks,
    [](Objects& o)
    {
      o.mapper->RemoveAllLabelMaterials();
      o.mapper->SetLabelMaterial(1, 0.9, 0.2, 0.1, 0.6);
    },
    false, Work::Display });
  // Over a multi-material description (the viewer's label list): a look
  // is a label class of its own, ahead of the description's.
  const auto described = [](Objects& o)
  {
    HeadFunctions(o);
    vtkNew<vtkMultiMaterialProperty> description;
    description->SetPreset("ct-organs");
    o.mapper->SetMultiMaterialProperty(description);
  };
  c.push_back({ "description-label-look", Input::HeadLabels, described,
    [](Objects& o) { o.mapper->SetLabelMaterial(1, 0.1, 0.9, 0.2, 1.0); } });
  c.push_back({ "description-label-look-opacity", Input::HeadLabels,
    [&](Objects& o)
    {
      described(o);
      o.mapper->SetLabelMaterial(1, 0.1, 0.9, 0.2, 1.0);
    },
    [](Objects& o) { o.mapper->SetLabelMaterial(1, 0.1, 0.9, 0.2, 0.1); } });
  c.push_back({ "description-label-look-set-again", Input::HeadLabels,
    [&](Objects& o)
    {
      described(o);
      o.mapper->SetLabelMaterial(1, 0.1, 0.9, 0.2, 1.0);
    },
    [](Objects& o)
    {
      o.mapper->RemoveAllLabelMaterials();
      o.mapper->SetLabelMaterial(1, 0.1, 0.9, 0.2, 1.0);
    },
    false, Work::Display });

  // The mapper's own settings.
  c.push_back({ "seed", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->SetSeed(kSeed + 1); } });
  c.push_back({ "maximum-bounces", Input::Head, Shaded, [](Objects& o) { o.mapper->SetMaximumBounces(1); } });
  c.push_back(
    { "shadow-extinction-scale", Input::Head, Shaded, [](Objects& o) { o.mapper->SetShadowExtinctionScale(1.0); } });
  c.push_back({ "sampler", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->SetSamplerToIndependent(); } });
  c.push_back({ "accelerator", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->SetAcceleratorToMacrocell(); } });
  c.push_back({ "no-accelerator", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->SetAcceleratorToNone(); } });
  c.push_back(
    { "environment-texture", Input::Head, Shaded, [](Objects& o) { o.mapper->SetEnvironmentTexture(o.environment); } });
  c.push_back({ "environment-intensity", Input::Head,
    [](Objects& o)
    {
      Shaded(o);
      o.mapper->SetEnvironmentTexture(o.environment);
    },
    [](Objects& o) { o.mapper->SetEnvironmentIntensity(3.0); } });
  c.push_back({ "environment-texels", Input::Head,
    [](Objects& o)
    {
      Shaded(o);
      o.mapper->SetEnvironmentTexture(o.environment);
    },
    [](Objects& o)
    {
      vtkImageData* sky = vtkImageData::SafeDownCast(o.environment->GetInputDataObject(0, 0));
      static_cast<float*>(sky->GetScalarPointer())[0] = 20.f;
      sky->Modified();
    } });
  c.push_back(
    { "clipping-plane", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->AddClippingPlane(o.plane); } });
  c.push_back({ "clipping-plane-moved", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      o.mapper->AddClippingPlane(o.plane);
    },
    [](Objects& o)
    {
      const double* origin = o.plane->GetOrigin();
      o.plane->SetOrigin(origin[0] + 20, origin[1], origin[2]);
    } });
  // The mapper compares what it traces by value: the same plane again (a
  // new object, as Slicer's pipeline makes at each update), a setting
  // changed and changed back, and a modification that changes nothing
  // keep the samples.
  c.push_back({ "clipping-plane-again", Input::Head,
    [](Objects& o)
    {
      HeadFunctions(o);
      o.mapper->AddClippingPlane(o.plane);
    },
    [](Objects& o)
    {
      vtkNew<vtkPlane> same;
      same->SetOrigin(o.plane->GetOrigin());
      same->SetNormal(o.plane->GetNormal());
      o.mapper->RemoveAllClippingPlanes();
      o.mapper->AddClippingPlane(same);
    },
    false, Work::Display });
  c.push_back({ "seed-changed-back", Input::Head, HeadFunctions,
    [](Objects& o)
    {
      o.mapper->SetSeed(kSeed + 1);
      o.mapper->SetSeed(kSeed);
    },
    false, Work::Display });
  c.push_back({ "modified-only", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->Modified(); }, false,
    Work::Display });
  // The image sample distances decide the still film's size: a distance
  // the still render does not use (AutoAdjust on: ImageSampleDistance; the
  // previews' largest) keeps the samples, one that sizes the film restarts.
  c.push_back({ "image-sample-distance-unused", Input::Head, HeadFunctions,
    [](Objects& o)
    {
      o.mapper->SetImageSampleDistance(2.0f);
      o.mapper->SetMaximumImageSampleDistance(4.0f);
    },
    false, Work::Display });
  c.push_back({ "minimum-image-sample-distance", Input::Head, HeadFunctions,
    [](Objects& o) { o.mapper->SetMinimumImageSampleDistance(2.0f); }, true, Work::Restart });
  c.push_back({ "cropping", Input::Head, HeadFunctions,
    [](Objects& o)
    {
      const double* b = o.mapper->GetBounds();
      o.mapper->SetCroppingRegionPlanes(b[0], 0.5 * (b[0] + b[1]), b[2], b[3], b[4], b[5]);
      o.mapper->SetCroppingRegionFlagsToSubVolume();
      o.mapper->CroppingOn();
    } });
  c.push_back(
    { "exposure", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->SetExposure(2.0); }, false, Work::Display });
  c.push_back({ "nothing", Input::Head, HeadFunctions, [](Objects&) {}, false, Work::Display });
  // A pixel's samples do not depend on the thread count (DESIGN.md rule 2):
  // the film is kept, and a fresh mapper on one thread makes the same film.
  c.push_back(
    { "threads", Input::Head, Shaded, [](Objects& o) { o.mapper->SetNumberOfThreads(1); }, false, Work::Display });
  c.push_back({ "tone-mapping", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->SetToneMappingToFilmic(); },
    false, Work::Display });
  c.push_back({ "unshaded-scattering", Input::Head, HeadFunctions, [](Objects& o) { o.mapper->UnshadedScatteringOn(); },
    true, Work::Translate });
  // Isosurfaces read the gradient magnitude: a proxy more (a rebuild);
  // another iso-value moves the extinction (a refit).
  c.push_back({ "isosurface-blend", Input::Head,
    [](Objects& o)
    {
      Shaded(o);
      o.property->GetIsoSurfaceValues()->SetValue(0, 1200);
    },
    [](Objects& o) { o.mapper->SetBlendModeToIsoSurface(); }, true, Work::Rebuild });
  c.push_back({ "iso-value", Input::Head,
    [](Objects& o)
    {
      Shaded(o);
      o.property->GetIsoSurfaceValues()->SetValue(0, 1200);
      o.mapper->SetBlendModeToIsoSurface();
    },
    [](Objects& o) { o.property->GetIsoSurfaceValues()->SetValue(0, 1600); } });

  // The work of the edits that do not only translate the property again.
  std::map<std::string, Work> work = { { "gradient-opacity-enabled", Work::Rebuild },
    { "gradient-opacity-disabled", Work::Rebuild }, { "independent-components-off", Work::Rebuild },
    { "independent-components-on", Work::Rebuild }, { "component-gradient-opacity", Work::Rebuild },
    { "label-gradient-opacity", Work::Rebuild }, { "mask-binary", Work::Rebuild }, { "seed", Work::Restart },
    { "maximum-bounces", Work::Restart }, { "shadow-extinction-scale", Work::Restart }, { "sampler", Work::Restart },
    { "accelerator", Work::Accelerator }, { "no-accelerator", Work::Accelerator },
    { "environment-texture", Work::Restart }, { "environment-intensity", Work::Restart },
    { "environment-texels", Work::Restart }, { "clipping-plane", Work::Restart },
    { "clipping-plane-moved", Work::Restart }, { "cropping", Work::Restart } };
  // Edits of what is not extinction (colours, shading, surfaces) keep the
  // majorants; a component weight between 0 and 1 scales the component's
  // colour, as VTK's GPU mapper does, not its extinction.
  for (const char* name : { "color-rgb-point", "color-rgb-to-gray", "color-gray-point", "shade-on", "shade-off",
         "ambient", "diffuse", "specular", "specular-power", "interpolation-nearest", "transfer-function-2d",
         "component-weight", "component-color-point", "label-color-point", "label-color-replaced", "label-material",
         "label-material-edited", "label-material-removed", "label-look-colour" })
    work[name] = Work::Translate;
  for (Case& x : c)
    if (auto it = work.find(x.name); it != work.end())
      x.work = it->second;
  return c;
}

std::vector<float> Film(vtkMultiMaterialVolumeMapper* mapper)
{
  vtkNew<vtkImageData> image;
  mapper->GetAccumulatedImage(image);
  vtkFloatArray* values = vtkFloatArray::SafeDownCast(image->GetPointData()->GetScalars());
  if (!values)
    return {};
  return std::vector<float>(values->GetPointer(0), values->GetPointer(0) + values->GetNumberOfValues());
}

// Values that differ (bits, so that NaN and -0 count), and the largest difference.
size_t Differences(const std::vector<float>& a, const std::vector<float>& b, double* largest)
{
  *largest = 0;
  if (a.size() != b.size())
    return std::max(a.size(), b.size());
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0)
    {
      ++n;
      *largest = std::max(*largest, static_cast<double>(std::abs(a[i] - b[i])));
    }
  return n;
}

struct Inputs
{
  vtkSmartPointer<vtkImageData> head, labels, twoComponents;
};

// One mapper with its own property, functions, texture and plane.
struct Pipeline
{
  vtkNew<vtkMultiMaterialVolumeMapper> mapper;
  vtkNew<vtkVolumeProperty> property;
  vtkNew<vtkPiecewiseFunction> opacity;
  vtkNew<vtkColorTransferFunction> color;
  vtkSmartPointer<vtkTexture> environment = EnvironmentTexture();
  vtkNew<vtkPlane> plane;
  Objects objects{ property, mapper, opacity, color, environment, plane };

  Pipeline(const Case& c, const Inputs& in)
  {
    vtkImageData* input = c.input == Input::TwoComponents ? in.twoComponents.Get() : in.head.Get();
    mapper->SetInputData(input);
    if (c.input == Input::HeadLabels)
      mapper->SetMaskInput(in.labels);
    mapper->SetBackendToCPU();
    mapper->SetNumberOfThreads(2);
    mapper->SetSeed(kSeed);
    mapper->SetSamplesPerRender(kSamples);
    mapper->SetMaximumSamples(kSamples);
    double centre[3];
    input->GetCenter(centre);
    plane->SetOrigin(centre);
    plane->SetNormal(1, 0.3, 0);
    c.setup(objects);
  }
};

// Renders the pipeline's mapper and property in the test's window; its film
// (empty unless it holds kSamples samples).
std::vector<float> Render(vtkRenderWindow* window, vtkVolume* volume, Pipeline& p)
{
  volume->SetMapper(p.mapper);
  volume->SetProperty(p.property);
  window->Render();
  if (p.mapper->GetAccumulatedSamples() != kSamples)
    return {};
  return Film(p.mapper);
}

bool RunCase(const Case& c, const Inputs& in, vtkRenderWindow* window, vtkRenderer* renderer, vtkVolume* volume)
{
  Pipeline a(c, in);
  volume->SetMapper(a.mapper);
  volume->SetProperty(a.property);
  renderer->ResetCamera();
  const std::vector<float> before = Render(window, volume, a);
  const Counts counts = CountsOf(a.mapper);
  c.edit(a.objects);
  const std::vector<float> edited = Render(window, volume, a);
  const Counts after = CountsOf(a.mapper);
  const Counts done = { after.builds - counts.builds, after.translations - counts.translations,
    after.restarts - counts.restarts, after.gridBuilds - counts.gridBuilds, after.gridRefits - counts.gridRefits };

  Pipeline b(c, in);
  c.edit(b.objects);
  const std::vector<float> fresh = Render(window, volume, b);

  double largest = 0, change = 0;
  const size_t differ = Differences(edited, fresh, &largest);
  const size_t changed = Differences(before, edited, &change);
  const bool ok = !before.empty() && !edited.empty() && !fresh.empty() && differ == 0 &&
    (c.changesImage ? changed > 0 : changed == 0) && WorkAsExpected(c.work, done);
  std::cout << (ok ? "ok   " : "FAIL ") << c.name << ": ";
  if (differ == 0)
    std::cout << "the film of a fresh mapper (" << fresh.size() << " values)";
  else
    std::cout << differ << " of " << fresh.size() << " values differ from a fresh mapper's (largest difference "
              << largest << ")";
  std::cout << "; the edit changed " << changed << " values"
            << (c.changesImage ? "" : " (documented as not used: 0 expected)") << "; A's scene builds +" << done.builds
            << ", translations +" << done.translations << ", restarts +" << done.restarts << ", grid builds +"
            << done.gridBuilds << ", grid refits +" << done.gridRefits << " (" << WorkName(c.work)
            << (WorkAsExpected(c.work, done) ? ")" : " expected)") << "\n";
  if (before.empty() || edited.empty() || fresh.empty())
    std::cout << "     a render did not accumulate " << kSamples << " samples\n";
  return ok;
}
}

int main(int argc, char* argv[])
{
  // The shared test volumes: -D, else MMRTM_SHARED_DATA_DIR in the
  // environment, else the build's (so that the planted-defect check can run
  // the program without arguments).
  const char* environment = std::getenv("MMRTM_SHARED_DATA_DIR");
  std::string data = environment && *environment ? environment : MMRTM_SHARED_DATA_DIR;
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "-D" && i + 1 < argc)
      data = argv[++i];
    else if (a == "--help" || a[0] == '-')
    {
      std::ostream& out = a == "--help" ? std::cout : std::cerr;
      out << "usage: " << argv[0] << " [-D DATA_DIR (" << data << ")] [CASE...]   (no CASE: all)\ncases:";
      for (const Case& c : Cases())
        out << " " << c.name;
      out << "\n";
      return a == "--help" ? 0 : 2;
    }
    else
      only.push_back(a);
  }

  Inputs in;
  vtkNew<vtkNrrdReader> reader;
  reader->SetFileName((data + "/ct_head_headsq.nrrd").c_str());
  // Every other voxel (32 x 32 x 47): the scene builds of 90 mappers are
  // most of the test's time, and state is what it tests, not detail.
  reader->Update(); // whole: the NRRD reader cannot read a part
  vtkNew<vtkImageShrink3D> shrink;
  shrink->SetInputData(reader->GetOutput());
  shrink->SetShrinkFactors(2, 2, 2);
  shrink->AveragingOff();
  shrink->Update();
  in.head = shrink->GetOutput();
  if (!in.head || in.head->GetNumberOfPoints() == 0)
  {
    std::cerr << "cannot read " << data << "/ct_head_headsq.nrrd\n";
    return 1;
  }
  in.labels = HeadLabels(in.head);
  in.twoComponents = TwoComponentVolume();

  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkVolume> volume;
  renderer->AddVolume(volume);
  renderer->SetBackground(0.1, 0.1, 0.1);
  renderer->GetActiveCamera()->Elevation(-70);
  renderer->GetActiveCamera()->OrthogonalizeViewUp();
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->SetSize(kSize, kSize);

  int failed = 0, run = 0;
  for (const Case& c : Cases())
  {
    if (!only.empty() && std::find(only.begin(), only.end(), c.name) == only.end())
      continue;
    ++run;
    failed += RunCase(c, in, window, renderer, volume) ? 0 : 1;
  }
  if (run == 0)
  {
    std::cerr << "no such case\n";
    return 2;
  }
  std::cout << failed << " of " << run << " edits failed\n";
  return failed ? 1 : 0;
}
