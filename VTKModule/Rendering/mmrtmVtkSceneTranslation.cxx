#include "mmrtmVtkSceneTranslation.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkLight.h>
#include <vtkLightCollection.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkVolumeProperty.h>

#include "derived_proxies.h"
#include "label_alignment.h"
#include "mmrtm/planted_defect.h"
#include "mmrtmImageDataConversion.h"
#include "mmrtmVolumePropertyFunctions.h"
#include "scene_json.h"

namespace mmrtm
{
namespace
{

// Sample positions over [lo, hi] (one point when the range is empty).
std::vector<float> Positions(std::array<float, 2> range)
{
  if (!(range[1] > range[0]))
    return { range[0] };
  std::vector<float> x(kTableSize);
  for (int i = 0; i < kTableSize; ++i)
    x[i] = range[0] + (range[1] - range[0]) * (float)i / (kTableSize - 1);
  return x;
}

int AddCurve(Scene& scene, const std::string& where, int proxy, const std::vector<float>& keys,
  const std::vector<float>& values, int channels)
{
  TransferFunctionDesc tf;
  tf.where = where;
  tf.type = TFType::CCTF;
  tf.proxy = proxy;
  tf.channels = channels;
  tf.keys = keys;
  tf.values = values;
  scene.tfs.push_back(std::move(tf));
  return (int)scene.tfs.size() - 1;
}

// VTK's opacity per unit distance as extinction: a slab `unit` thick
// transmits 1 - alpha.
float Extinction(double alpha, double unit)
{
  const double sigma_t = -std::log(1.0 - std::clamp(alpha, 0.0, 0.9999)) / unit;
  return (float)(Planted(Defect::VtkExtinction) ? 1.01 * sigma_t : sigma_t);
}

double UnitDistance(vtkVolumeProperty* property, int component)
{
  const double d = property->GetScalarOpacityUnitDistance(component);
  return std::isnan(d) ? 1.0 : std::max(d, 1e-6); // NaN: VTK's default; 0 or less: opaque (Classifier clamps)
}

// The material's colour (its albedo and the functions bound to it) as its
// emission, and no albedo: it glows and scatters nothing.
void Glow(MaterialDesc& m)
{
  for (MaterialDesc::Binding& b : m.bindings)
    if (b.quantity == Quantity::Albedo)
      b.quantity = Quantity::Emission;
  for (int c = 0; c < 3; ++c)
  {
    m.base[QuantityOffset(Quantity::Emission) + c] = m.base[QuantityOffset(Quantity::Albedo) + c];
    m.base[QuantityOffset(Quantity::Albedo) + c] = 0.f;
  }
}

// Shade, Specular and SpecularPower on a material (the rule in the header).
void ApplyShading(vtkVolumeProperty* property, int component, const TranslationOptions& options, MaterialDesc& m)
{
  const bool shade = property->GetShade(component) != 0;
  m.base[QuantityOffset(Quantity::SurfaceProbability)] =
    shade ? (options.localLighting ? 1.f : kShadedSurfaceProbability) : 0.f;
  const double specular = property->GetSpecular(component),
               power = std::max(property->GetSpecularPower(component), 0.0);
  const double roughness = std::pow(2.0 / (power + 2.0), 0.25) * (Planted(Defect::VtkSpecularPower) ? 1.01 : 1.0);
  m.base[QuantityOffset(Quantity::Roughness)] = specular > 0.0 ? (float)std::clamp(roughness, 0.05, 1.0) : 1.f;
  if (!shade && !options.unshadedScatters)
    Glow(m);
}

// The colour of a material, scattered or glowing, times `factor`.
void ScaleColour(MaterialDesc& m, float factor)
{
  for (int c = 0; c < 3; ++c)
  {
    m.base[QuantityOffset(Quantity::Albedo) + c] *= factor;
    m.base[QuantityOffset(Quantity::Emission) + c] *= factor;
  }
}

bool IsConstantOne(vtkPiecewiseFunction* f)
{
  if (!f || f->GetSize() == 0)
    return true;
  double node[4];
  for (int i = 0; i < f->GetSize(); ++i)
  {
    f->GetNodeValue(i, node);
    if (node[1] != 1.0)
      return false;
  }
  return true;
}

} // namespace

bool UsesGradientOpacity(vtkVolumeProperty* property, int component)
{
  return property && !property->GetDisableGradientOpacity(component) &&
    !IsConstantOne(HeldGradientOpacity(property, component));
}

namespace
{

// The property's functions with their non-finite node values read as 0 at
// their node (a NaN x drops the node): VTK interpolates a NaN node value
// into both neighbouring segments, which would empty them; 0 at the node
// keeps the neighbours' ramps. Functions without such values are used as
// they are; repaired copies live as long as this object.
class FiniteFunctions
{
public:
  vtkPiecewiseFunction* Of(vtkPiecewiseFunction* f)
  {
    return Repaired<4>(f, [](vtkPiecewiseFunction* c, const double* n) { c->AddPoint(n[0], n[1], n[2], n[3]); });
  }
  vtkColorTransferFunction* Of(vtkColorTransferFunction* f)
  {
    return Repaired<6>(
      f, [](vtkColorTransferFunction* c, const double* n) { c->AddRGBPoint(n[0], n[1], n[2], n[3], n[4], n[5]); });
  }
  // A function made here (a default), kept as long as this object.
  template <class F>
  F* Keep(vtkSmartPointer<F> f)
  {
    keep_.emplace_back(f);
    return f;
  }
  int replaced = 0; // node values read as 0, nodes dropped

private:
  // `f`, or a copy with its nodes (Count doubles each) repaired and added
  // back by `add`.
  template <int Count, class F, class Add>
  F* Repaired(F* f, Add add)
  {
    if (!f || Finite<Count>(f))
      return f;
    vtkNew<F> copy;
    copy->DeepCopy(f);
    copy->RemoveAllPoints();
    double node[Count];
    for (int i = 0; i < f->GetSize(); ++i)
    {
      f->GetNodeValue(i, node);
      if (Repair(node, Count))
        add(copy.Get(), node);
    }
    keep_.emplace_back(copy.Get());
    return copy;
  }
  template <int Count, class F>
  static bool Finite(F* f)
  {
    double node[Count];
    for (int i = 0; i < f->GetSize(); ++i)
    {
      f->GetNodeValue(i, node);
      for (int k = 0; k < Count; ++k)
        if (!std::isfinite(node[k]))
          return false;
    }
    return true;
  }
  // Values to 0, midpoint and sharpness (the last two) to VTK's defaults;
  // false: drop the node (its position is not finite).
  bool Repair(double* node, int count)
  {
    if (!std::isfinite(node[0]))
      return ++replaced, false;
    const double defaults[2] = { 0.5, 0.0 };
    for (int k = 1; k < count; ++k)
      if (!std::isfinite(node[k]))
        node[k] = k >= count - 2 ? defaults[k - (count - 2)] : 0.0, ++replaced;
    return true;
  }
  std::vector<vtkSmartPointer<vtkObject>> keep_;
};

// The functions of one material: the property's component functions, or a
// label's (null members fall back to the component's).
struct MaterialFunctions
{
  vtkPiecewiseFunction* opacity = nullptr;
  vtkColorTransferFunction* color = nullptr; // null with grey: `grey` instead
  vtkPiecewiseFunction* grey = nullptr;
  vtkPiecewiseFunction* gradientOpacity = nullptr; // null: not used
};

// Component c's own functions (its gradient opacity when it is used); VTK's
// default where the property holds none, made here, not in the property.
MaterialFunctions ComponentFunctions(vtkVolumeProperty* property, int c, FiniteFunctions& finite)
{
  MaterialFunctions f;
  vtkPiecewiseFunction* opacity = HeldScalarOpacity(property, c);
  f.opacity = finite.Of(opacity ? opacity : finite.Keep(DefaultScalarOpacity()));
  if (property->GetColorChannels(c) == 3)
  {
    vtkColorTransferFunction* color = HeldRGBTransferFunction(property, c);
    f.color = finite.Of(color ? color : finite.Keep(DefaultRGBTransferFunction()));
  }
  else
  {
    vtkPiecewiseFunction* grey = HeldGrayTransferFunction(property, c);
    f.grey = finite.Of(grey ? grey : finite.Keep(DefaultGrayTransferFunction()));
  }
  if (UsesGradientOpacity(property, c))
    f.gradientOpacity = finite.Of(HeldGradientOpacity(property, c));
  return f;
}

// The extinction of isosurfaces (the rule in the header): a piecewise-
// constant factor over the scalars, tau(v) / (2 delta) in the band
// (v - delta, v + delta) of each iso-value v and 0 elsewhere, times the
// gradient magnitude, so that a ray crossing a band along the gradient
// meets the optical depth tau(v) (its path through the band is
// 2 delta / |grad|); at an angle it meets more, as a thin film does.
void AddIsoSurfaces(const std::string& name, vtkPiecewiseFunction* opacity, double unitDistance,
  const TranslationOptions& options, const ProxyLayout& proxies, Scene& scene, MaterialDesc& m)
{
  const float delta = std::max(kIsoBandFraction * (proxies.scalarRange[1] - proxies.scalarRange[0]), 1e-6f);
  TransferFunctionDesc band;
  band.where = name + " isosurfaces";
  band.type = TFType::CPCTF;
  band.proxy = 0;
  band.channels = 1;
  for (double v : options.isoValues)
  {
    if (!std::isfinite(v))
      continue;
    const float depth = Extinction(opacity->GetValue(v), unitDistance) * options.isoSampleDistance;
    band.keys.insert(band.keys.end(), { (float)v - delta, (float)v + delta });
    band.values.push_back(depth / (2.f * delta));
  }
  if (band.values.empty()) // no iso-value: nothing shows, as in VTK
    band.keys = { 0.f, 0.f }, band.values = { 0.f };
  scene.tfs.push_back(std::move(band)); // 0 outside the bands
  m.bindings.push_back({ (int)scene.tfs.size() - 1, Quantity::Density });
  const float top = std::max(proxies.gradientRange[1], 1.f);
  m.bindings.push_back(
    { AddCurve(scene, name + " isosurface gradient", proxies.gradient, { 0.f, top }, { 0.f, top }, 1),
      Quantity::Density });
}

// `valueProxy` holds the values the functions read (the scalars, or an
// independent component), over `valueRange`.
MaterialDesc MakeMaterial(const std::string& name, const MaterialFunctions& f, vtkVolumeProperty* property,
  int component, const ProxyLayout& proxies, const TranslationOptions& options, Scene& scene, int valueProxy = 0,
  const std::array<float, 2>* valueRange = nullptr)
{
  MaterialDesc m;
  m.name = name;
  const std::vector<float> x = Positions(valueRange ? *valueRange : proxies.scalarRange);
  const int n = (int)x.size();

  // Extinction from opacity per unit distance, over the opacity component
  // (dependent components) or the scalars.
  const int opacityProxy = proxies.opacity >= 0 ? proxies.opacity : valueProxy;
  const std::vector<float> xo = proxies.opacity >= 0 ? Positions(proxies.opacityRange) : x;
  const int no = (int)xo.size();
  std::vector<float> alpha(no), density(no);
  if (no > 1)
    f.opacity->GetTable(xo.front(), xo.back(), no, alpha.data());
  else
    alpha[0] = (float)f.opacity->GetValue(xo[0]);
  const bool labelDefect = Planted(Defect::VtkLabelFunctions) && name.rfind("label ", 0) == 0;
  for (int i = 0; i < no; ++i)
    density[i] = Extinction(alpha[i], UnitDistance(property, component)) * (labelDefect ? 1.01f : 1.f);
  m.base[QuantityOffset(Quantity::Density)] = 1.f;
  const bool iso = options.isosurface && proxies.gradient >= 0 && proxies.independent <= 1 && proxies.opacity < 0;
  if (iso)
    AddIsoSurfaces(name, f.opacity, UnitDistance(property, component), options, proxies, scene, m);
  else
    m.bindings.push_back(
      { AddCurve(scene, name + " scalar opacity", opacityProxy, xo, density, 1), Quantity::Density });

  // Gradient opacity multiplies the extinction.
  if (f.gradientOpacity && proxies.gradient >= 0)
  {
    const std::vector<float> g = Positions(proxies.gradientRange);
    std::vector<float> gv(g.size());
    for (size_t i = 0; i < g.size(); ++i)
      gv[i] = (float)std::clamp(f.gradientOpacity->GetValue(g[i]), 0.0, 1.0) *
        (Planted(Defect::VtkGradientOpacity) ? 0.99f : 1.f);
    m.bindings.push_back(
      { AddCurve(scene, name + " gradient opacity", proxies.gradient, g, gv, 1), Quantity::Density });
  }
  // A binary mask: empty where it is 0.
  if (proxies.binaryMask >= 0)
    m.bindings.push_back(
      { AddCurve(scene, "binary mask", proxies.binaryMask, { 0.f, 1.f }, { 0.f, 1.f }, 1), Quantity::Density });

  // Albedo: the RGB components themselves (4 dependent components), one
  // channel per proxy, multiplied.
  if (proxies.rgb[0] >= 0)
  {
    for (int c = 0; c < 3; ++c)
    {
      std::vector<float> values = { 1.f, 1.f, 1.f, 1.f, 1.f, 1.f };
      values[c] = 0.f;
      values[3 + c] = 1.f;
      const float scale = proxies.colorScale * (Planted(Defect::VtkDependentRgb) ? 1.01f : 1.f);
      m.bindings.push_back(
        { AddCurve(scene, name + " rgb", proxies.rgb[c], { 0.f, scale }, values, 3), Quantity::Albedo });
    }
  }
  else
  {
    // Albedo from colour.
    std::vector<float> rgb(3 * n);
    for (int i = 0; i < n; ++i)
    {
      double c[3];
      if (f.color)
      {
        f.color->GetColor(x[i], c);
      }
      else
      {
        c[0] = c[1] = c[2] = f.grey->GetValue(x[i]);
      }
      for (int k = 0; k < 3; ++k)
        rgb[3 * i + k] = (float)std::clamp(c[k], 0.0, 1.0) * (Planted(Defect::VtkColor) ? 0.99f : 1.f);
    }
    m.bindings.push_back({ AddCurve(scene, name + " color", valueProxy, x, rgb, 3), Quantity::Albedo });
  }
  ApplyShading(property, component, options, m);
  if (iso && property->GetShade(component))
    m.base[QuantityOffset(Quantity::SurfaceProbability)] = 1.f; // a surface, not a medium
  return m;
}

} // namespace

// The property's 2D transfer function, when it is the one in use.
vtkImageData* TransferFunction2D(vtkVolumeProperty* property, int component)
{
  if (property->GetTransferFunctionMode() != vtkVolumeProperty::TF_2D)
    return nullptr;
  vtkImageData* f = property->GetTransferFunction2D(component);
  if (!f || !f->GetPointData()->GetScalars() || f->GetPointData()->GetScalars()->GetNumberOfComponents() != 4)
    return nullptr;
  return f;
}

bool NeedsGradientProxy(vtkVolumeProperty* property, int component, bool labels)
{
  if (UsesGradientOpacity(property, component) || TransferFunction2D(property, component))
    return true;
  if (labels)
    for (int label : property->GetLabelMapLabels())
      if (!IsConstantOne(property->GetLabelGradientOpacity(label)))
        return true;
  return false;
}

namespace
{

// A 2D transfer function (x: scalar value, y: gradient magnitude, RGBA) as
// materials: the scalar axis is cut into at most kMax2DBands bands, each a
// material whose extinction and albedo are CCTFs over the gradient
// magnitude (the band's mean over its columns), chosen by an MPCTF over the
// scalars. Exact in the gradient direction; in the scalar direction the
// table is piecewise constant per band (one band per column up to 64
// columns), where VTK interpolates between columns.
constexpr int kMax2DBands = 64;

void Add2DMaterials(vtkImageData* table, vtkVolumeProperty* property, int component, const ProxyLayout& proxies,
  const TranslationOptions& options, Scene& scene)
{
  int dims[3];
  table->GetDimensions(dims);
  double origin[3], spacing[3];
  table->GetOrigin(origin);
  table->GetSpacing(spacing);
  vtkDataArray* rgba = table->GetPointData()->GetScalars();
  const int nx = dims[0], ny = dims[1];
  const int bands = std::min(nx, kMax2DBands);
  std::vector<float> g(ny);
  for (int j = 0; j < ny; ++j)
    g[j] = (float)(origin[1] + j * spacing[1]);
  if (ny == 1)
    g.push_back(g[0] + 1.f); // a constant in the gradient: two equal points
  TransferFunctionDesc selector;
  selector.where = "2D transfer function";
  selector.type = TFType::MPCTF;
  selector.proxy = 0;
  selector.channels = 1;
  for (int b = 0; b < bands; ++b)
  {
    const int i0 = b * nx / bands, i1 = (b + 1) * nx / bands; // columns [i0, i1)
    std::vector<float> density, albedo;
    for (int j = 0; j < (int)g.size(); ++j)
    {
      const int row = std::min(j, ny - 1);
      double sum[4] = { 0, 0, 0, 0 };
      for (int i = i0; i < i1; ++i)
        for (int c = 0; c < 4; ++c)
          sum[c] += rgba->GetComponent(i + (vtkIdType)nx * row, c) / (i1 - i0);
      density.push_back(Extinction(sum[3], UnitDistance(property, component)));
      for (int c = 0; c < 3; ++c)
        albedo.push_back((float)std::clamp(sum[c], 0.0, 1.0));
    }
    // The band covers its columns' cells: from half a column below the
    // first to half a column above the last (the outer bands extend far).
    const double lo = b == 0 ? -1e30 : origin[0] + (i0 - 0.5) * spacing[0];
    const double hi = b == bands - 1 ? 1e30 : origin[0] + (i1 - 0.5) * spacing[0];
    MaterialDesc m;
    m.name = "2D band " + std::to_string(b);
    m.base[QuantityOffset(Quantity::Density)] = 1.f;
    m.bindings.push_back({ AddCurve(scene, m.name + " opacity", proxies.gradient, g, density, 1), Quantity::Density });
    m.bindings.push_back({ AddCurve(scene, m.name + " color", proxies.gradient, g, albedo, 3), Quantity::Albedo });
    ApplyShading(property, component, options, m);
    selector.keys.push_back((float)lo);
    selector.keys.push_back((float)hi);
    selector.materials.push_back((int)scene.materials.size());
    scene.materials.push_back(std::move(m));
  }
  scene.tfs.push_back(std::move(selector));
  scene.selectors.push_back((int)scene.tfs.size() - 1);
}

} // namespace

namespace
{

// The translation's transfer function of `type` over the label proxy
// (TranslateMaterials makes at most one of each: the labels' material
// selector, an MDPTF, and the gate that keeps the other materials off the
// labels that have functions, a CPCTF), or -1.
int LabelTransferFunction(const Scene& scene, int labelProxy, TFType type)
{
  for (size_t i = 0; i < scene.tfs.size(); ++i)
    if (scene.tfs[i].proxy == labelProxy && scene.tfs[i].type == type)
      return static_cast<int>(i);
  return -1;
}

// Returns how many function node values were not finite.
int TranslateMaterials(vtkVolumeProperty* property, int component, const ProxyLayout& proxies,
  const TranslationOptions& options, Scene& scene)
{
  FiniteFunctions finite;
  scene.tfs.clear();
  scene.materials.clear();
  scene.selectors.clear();
  scene.additiveMaterials = false;
  if (proxies.independent > 1)
  {
    // A material per component, mixed additively; each reads its own proxy.
    for (int c = 0; c < proxies.independent; ++c)
    {
      MaterialFunctions f = ComponentFunctions(property, c, finite);
      ProxyLayout own = proxies; // this component's gradient proxy, if there was room for one
      own.gradient = proxies.componentGradient[c];
      own.gradientRange = proxies.componentGradientRanges[c];
      MaterialDesc m = MakeMaterial(
        "component " + std::to_string(c), f, property, c, own, options, scene, c, &proxies.componentRanges[c]);
      // VTK's GPU mapper composites a sample of independent components as
      // premultiplied colour sum(w_i a_i c_i) over opacity
      // sum(a_i^2) / sum(w_i a_i) (vtkVolumeShaderComposer.h): a component
      // alone has opacity a / w and colour w^2 c, so where it is opaque the
      // weight scales its colour by w^2 and its coverage hardly changes.
      // Ours keeps the component's extinction and scales its colour by
      // w^2; weight 0 removes it, as VTK drops it where it is alone (VTK's
      // opacity a / w grows without bound below that). vtkVolumeProperty
      // clamps weights to [0, 1]; NaN stays NaN, counted by
      // ReplaceNonFinite (the component then holds nothing).
      const double w = property->GetComponentWeight(c);
      m.base[QuantityOffset(Quantity::Density)] = std::isnan(w) ? NAN : w > 0.0 ? 1.f : 0.f;
      ScaleColour(m, std::isnan(w) ? 0.f : (float)(w * w) * (Planted(Defect::VtkComponentWeight) ? 0.99f : 1.f));
      scene.materials.push_back(std::move(m));
    }
    scene.additiveMaterials = true;
    scene.defaultMaterial = kNoMaterial;
    return finite.replaced;
  }
  const MaterialFunctions main = ComponentFunctions(property, component, finite);
  if (vtkImageData* table = TransferFunction2D(property, component); table && proxies.gradient >= 0)
  {
    Add2DMaterials(table, property, component, proxies, options, scene); // no default: outside the bands is empty
    scene.defaultMaterial = kNoMaterial;
  }
  else
  {
    scene.materials.push_back(MakeMaterial("volume", main, property, component, proxies, options, scene));
    scene.defaultMaterial = 0;
  }

  // Labels: a material each, picked by an MDPTF over the label map.
  if (proxies.labels < 0)
    return finite.replaced;
  TransferFunctionDesc selector;
  selector.where = "label map";
  selector.type = TFType::MDPTF;
  selector.proxy = proxies.labels;
  selector.channels = 1;
  for (int label : property->GetLabelMapLabels())
  {
    if (label == 0)
      continue; // 0 is unlabelled: the component's functions
    MaterialFunctions f = main;
    if (vtkPiecewiseFunction* o = property->GetLabelScalarOpacity(label))
      f.opacity = finite.Of(o);
    if (vtkColorTransferFunction* c = property->GetLabelColor(label))
      f.color = finite.Of(c), f.grey = nullptr;
    if (vtkPiecewiseFunction* g = property->GetLabelGradientOpacity(label))
      f.gradientOpacity = IsConstantOne(g) ? nullptr : finite.Of(g);
    selector.keys.push_back((float)label);
    selector.materials.push_back((int)scene.materials.size());
    scene.materials.push_back(
      MakeMaterial("label " + std::to_string(label), f, property, component, proxies, options, scene));
  }
  if (selector.keys.empty())
    return finite.replaced;
  // VTK's GPU mapper classifies a labelled voxel by its label's functions
  // alone: where the label's opacity is 0 the voxel is empty, it does not
  // fall back to the component's functions. The classifier's priority rule
  // falls back (the label wins only where its density is above zero), so
  // the materials that are not labels' are gated off the labels that have
  // functions: a density factor over the label map, 0 at those labels and
  // 1 at every other value (0, and labels without functions, which VTK
  // classifies with the component's functions).
  TransferFunctionDesc gate;
  gate.where = "label map: labels with functions";
  gate.type = TFType::CPCTF;
  gate.proxy = proxies.labels;
  gate.channels = 1;
  for (float label : selector.keys)
  {
    gate.keys.insert(gate.keys.end(), { label - 0.5f, label + 0.5f });
    gate.values.push_back(0.f);
  }
  gate.keys.insert(gate.keys.end(), { -kInfinity, kInfinity }); // the first matching range wins
  gate.values.push_back(1.f);
  scene.tfs.push_back(std::move(gate));
  const int firstLabelMaterial = selector.materials.front();
  for (int m = 0; m < firstLabelMaterial; ++m)
    scene.materials[m].bindings.push_back({ (int)scene.tfs.size() - 1, Quantity::Density });
  scene.tfs.push_back(std::move(selector));
  scene.selectors.insert(scene.selectors.begin(), (int)scene.tfs.size() - 1); // labels first
  return finite.replaced;
}

// NaN in (clamped or not) reaches the TF values and material bases; 0 in
// their place (no extinction, black), counted.
int ReplaceNonFinite(Scene& scene)
{
  int replaced = 0;
  auto fix = [&](float& v)
  {
    if (!std::isfinite(v))
      v = 0.f, ++replaced;
  };
  for (TransferFunctionDesc& tf : scene.tfs)
    for (float& v : tf.values)
      fix(v);
  for (MaterialDesc& m : scene.materials)
    for (float& v : m.base)
      fix(v);
  return replaced;
}

} // namespace

int SetMaterialsFromProperty(vtkVolumeProperty* property, int component, const ProxyLayout& proxies,
  const TranslationOptions& options, Scene& scene)
{
  const int nodes = TranslateMaterials(property, component, proxies, options, scene);
  return nodes + ReplaceNonFinite(scene);
}

bool AnyMaterialScatters(const Scene& scene)
{
  for (const MaterialDesc& m : scene.materials)
    for (int c = 0; c < 3; ++c)
      if (m.base[QuantityOffset(Quantity::Albedo) + c] > 0.f)
        return true;
  return false;
}

void SetLabelLook(int label, const LabelLook& look, vtkVolumeProperty* property, int component,
  const ProxyLayout& proxies, const TranslationOptions& options, Scene& scene)
{
  if (proxies.labels < 0)
    return;
  const nlohmann::json rule = LabelMaterial(look);
  MaterialDesc m;
  m.name = "label " + std::to_string(label);
  m.base[QuantityOffset(Quantity::Density)] =
    rule["density"].get<float>() * (Planted(Defect::VtkLabelMaterial) ? 0.99f : 1.f);
  for (int c = 0; c < 3; ++c)
    m.base[QuantityOffset(Quantity::Albedo) + c] = rule["albedo"][c].get<float>();
  ApplyShading(property, component, options, m);
  // A look follows the one label rule (a hidden label shows the volume
  // property): the label leaves the gate that VTK's label functions put it
  // in.
  if (const int g = LabelTransferFunction(scene, proxies.labels, TFType::CPCTF); g >= 0)
  {
    TransferFunctionDesc& gate = scene.tfs[g];
    for (size_t i = 0; i + 1 < gate.values.size(); ++i)
      if (gate.keys[2 * i] == label - 0.5f)
      {
        gate.keys.erase(gate.keys.begin() + 2 * i, gate.keys.begin() + 2 * i + 2);
        gate.values.erase(gate.values.begin() + i);
        break;
      }
  }
  if (const int index = scene.MaterialIndex(m.name); index >= 0)
  {
    scene.materials[index] = std::move(m); // the property's label functions made it: the selector has it
    return;
  }
  // The label selector (SetMaterialsFromProperty puts it first), made when
  // the property has no label functions.
  const int s = LabelTransferFunction(scene, proxies.labels, TFType::MDPTF);
  TransferFunctionDesc* selector = s >= 0 ? &scene.tfs[s] : nullptr;
  if (!selector)
  {
    TransferFunctionDesc tf;
    tf.where = "label map";
    tf.type = TFType::MDPTF;
    tf.proxy = proxies.labels;
    tf.channels = 1;
    scene.tfs.push_back(std::move(tf));
    scene.selectors.insert(scene.selectors.begin(), (int)scene.tfs.size() - 1);
    selector = &scene.tfs.back();
  }
  const auto at = std::lower_bound(selector->keys.begin(), selector->keys.end(), (float)label);
  const auto offset = at - selector->keys.begin();
  selector->keys.insert(at, (float)label);
  selector->materials.insert(selector->materials.begin() + offset, (int)scene.materials.size());
  scene.materials.push_back(std::move(m));
}

void SetLabelMaterialParameters(int label, const std::string& json, Scene& scene)
{
  const std::string where = "label " + std::to_string(label) + " material";
  const nlohmann::json doc = ParseJson(json, where);
  if (!doc.is_object())
    throw InputError(where + ": expected a JSON object");
  const int index = scene.MaterialIndex("label " + std::to_string(label));
  if (index < 0)
    return;
  MaterialDesc& m = scene.materials[index];
  auto number = [&](const std::string& key, const nlohmann::json& v, float lo, float hi)
  {
    if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi))
      throw InputError(
        where + "." + key + ": expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v.get<float>();
  };
  for (const auto& [key, value] : doc.items())
  {
    if (key == "roughness")
      m.base[QuantityOffset(Quantity::Roughness)] = number(key, value, 0.f, 1.f);
    else if (key == "metallic")
      m.base[QuantityOffset(Quantity::Metallic)] = number(key, value, 0.f, 1.f);
    else if (key == "surface_probability")
      m.base[QuantityOffset(Quantity::SurfaceProbability)] = number(key, value, 0.f, 1.f);
    else if (key == "anisotropy")
      m.base[QuantityOffset(Quantity::Anisotropy)] = number(key, value, -0.99f, 0.99f);
    else if (key == "emission")
    {
      if (!value.is_array() || value.size() != 3)
        throw InputError(where + ".emission: expected [r, g, b]");
      for (int c = 0; c < 3; ++c)
        m.base[QuantityOffset(Quantity::Emission) + c] = number(key, value[c], 0.f, 1e6f);
    }
    else
      throw InputError(
        where + ": unknown key '" + key + "' (roughness, metallic, surface_probability, anisotropy, emission)");
  }
}

ProxyLayout BuildProxies(vtkVolumeProperty* property, vtkImageData* input, vtkDataArray* scalars, vtkImageData* mask,
  int dependent, int independent, bool needGradient, bool labels, Scene& scene,
  const std::function<void(const std::string&)>& warn)
{
  scene.proxies.clear();
  ProxyLayout layout;
  auto component = [&](int c, const char* name)
  {
    scene.proxies.push_back(ImageDataToHostVolume(input, scalars, c, name, Interpolation::Trilinear));
    return static_cast<int>(scene.proxies.size()) - 1;
  };
  component(0, dependent == 4 ? "red" : "scalars");
  layout.scalarRange = scene.proxies[0].ValueRange();
  scene.gradientProxy = 0;
  if (independent)
  {
    layout.independent = independent;
    layout.componentRanges[0] = layout.scalarRange;
    for (int c = 1; c < independent; ++c)
      layout.componentRanges[c] = scene.proxies[component(c, "component")].ValueRange();
    // Gradient magnitudes of the components with gradient opacity, while
    // there is room among the proxies.
    for (int c = 0; c < independent; ++c)
    {
      if (!UsesGradientOpacity(property, c))
        continue;
      if (scene.proxies.size() >= static_cast<size_t>(kMaxProxies))
      {
        warn("no room for the gradient of component " + std::to_string(c) + ": its gradient opacity is not used");
        continue;
      }
      layout.componentGradient[c] = static_cast<int>(scene.proxies.size());
      scene.proxies.push_back(GradientMagnitudeProxy(scene.proxies[c], "gradient"));
      layout.componentGradientRanges[c] = scene.proxies.back().ValueRange();
    }
  }
  if (dependent == 2)
  {
    layout.opacity = component(1, "opacity");
  }
  else if (dependent == 4)
  {
    layout.rgb[0] = 0;
    layout.rgb[1] = component(1, "green");
    layout.rgb[2] = component(2, "blue");
    layout.opacity = component(3, "opacity");
    float top = 0.f;
    for (int c = 0; c < 3; ++c)
      top = std::max(top, scene.proxies[c].ValueRange()[1]);
    layout.colorScale = scalars->GetDataType() == VTK_UNSIGNED_CHAR ? 255.f : std::max(top, 1e-6f);
  }
  if (layout.opacity >= 0)
  {
    layout.opacityRange = scene.proxies[layout.opacity].ValueRange();
    scene.gradientProxy = layout.opacity; // VTK shades dependent data by the opacity component
  }
  if (needGradient)
  {
    const int source = scene.gradientProxy;
    layout.gradient = static_cast<int>(scene.proxies.size());
    scene.proxies.push_back(GradientMagnitudeProxy(scene.proxies[source], "gradient"));
    layout.gradientRange = scene.proxies.back().ValueRange();
  }
  if (mask)
  {
    // Labels are never interpolated; a mask on another grid is put on
    // the input's by nearest neighbour in world space.
    HostVolume m =
      ImageDataToHostVolume(mask, nullptr, 0, labels ? "label map" : "mask", Interpolation::Nearest);
    m = AlignLabelsToVolume(std::move(m), scene.proxies[0]);
    (labels ? layout.labels : layout.binaryMask) = static_cast<int>(scene.proxies.size());
    scene.proxies.push_back(std::move(m));
  }
  if (scene.proxies.size() > kMaxProxies)
    throw InputError("this combination of components, gradient opacity and mask needs " +
      std::to_string(scene.proxies.size()) + " proxy volumes; at most " + std::to_string(kMaxProxies) +
      " are supported");
  return layout;
}

void SetCameraFromVtk(vtkCamera* camera, Scene& scene)
{
  CameraDesc& c = scene.camera;
  c.autoFrame = false;
  const double* p = camera->GetPosition();
  const double* f = camera->GetFocalPoint();
  const double* u = camera->GetViewUp();
  c.position = { (float)p[0], (float)p[1], (float)p[2] };
  c.lookAt = { (float)f[0], (float)f[1], (float)f[2] };
  c.up = { (float)u[0], (float)u[1], (float)u[2] };
  c.lensRadius = 0.f;
  const double* center = camera->GetWindowCenter();
  c.windowCenter[0] = (float)center[0];
  c.windowCenter[1] = (float)center[1];
  if (camera->GetParallelProjection())
  {
    c.projection = Projection::Orthographic;
    c.orthoHeight = (float)(2.0 * camera->GetParallelScale());
  }
  else
  {
    c.projection = Projection::Perspective;
    c.fovY = (float)camera->GetViewAngle();
  }
}

void SetLightsFromVtk(vtkRenderer* renderer, vtkVolumeProperty* property, Scene& scene)
{
  scene.lights.clear();
  scene.cameraLights.clear();
  const double diffuse = std::max(property->GetDiffuse(0), 0.0);
  vtkLightCollection* lights = renderer->GetLights();
  lights->InitTraversal();
  while (vtkLight* light = lights->GetNextItem())
  {
    if (!light->GetSwitch() || light->GetIntensity() <= 0.0)
      continue;
    double p[3], f[3];
    light->GetTransformedPosition(p);
    light->GetTransformedFocalPoint(f);
    const Vec3 position{ (float)p[0], (float)p[1], (float)p[2] }, focal{ (float)f[0], (float)f[1], (float)f[2] };
    const Vec3 toLight = position - focal;
    const float distance = Length(toLight);
    if (!(distance > 0.f))
      continue;
    const double* col = light->GetDiffuseColor();
    const float scale = kPi * (float)(light->GetIntensity() * diffuse) * (Planted(Defect::VtkDiffuse) ? 0.99f : 1.f);
    Light l;
    l.L = RGB((float)col[0] * scale, (float)col[1] * scale, (float)col[2] * scale);
    if (light->GetPositional())
    {
      l.type = LightType::Point;
      l.vector = position;
      l.L = l.L * (distance * distance); // irradiance pi * intensity at the focal point
    }
    else
    {
      l.type = LightType::Directional;
      l.vector = toLight / distance;
      // A headlight or camera light leaves from where it is, beside the
      // camera: with the camera inside the volume, the tissue behind it
      // does not shadow what it sees (from infinitely far, it would).
      if (light->LightTypeIsHeadlight() || light->LightTypeIsCameraLight())
        l.start = Dot(position, l.vector);
    }
    scene.lights.push_back(l);
  }
  const float ambient = (float)property->GetAmbient(0) * (Planted(Defect::VtkAmbient) ? 0.99f : 1.f);
  scene.environment = ambient > 0.f ? EnvironmentMap::Constant(RGB(ambient, ambient, ambient)) : nullptr;
}

} // namespace mmrtm
