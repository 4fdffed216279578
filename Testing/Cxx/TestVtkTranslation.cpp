// The translation of a vtkVolumeProperty into the tracer's scene
// (VTKModule/Rendering/mmrtmVtkSceneTranslation.h), rule by rule, against
// VTK's own definitions: the values VTK's functions give
// (vtkPiecewiseFunction::GetValue, vtkColorTransferFunction::GetColor),
// Beer-Lambert for the opacity per unit distance, vtkImageGradientMagnitude
// for the gradient magnitude. Each check says the smallest error it
// catches; a planted defect of 1 % in each rule fails it
// (Testing/PlantedDefects, Documentation/vtk-mapper.md "How the translation
// is checked").
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <vtkColorTransferFunction.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkImageGradientMagnitude.h>
#include <vtkLight.h>
#include <vtkMatrix3x3.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderer.h>
#include <vtkVolumeProperty.h>

#include "ExpectAgreement.h"
#include "TestSceneHelpers.h"
#include "derived_proxies.h"
#include "mmrtm/tracking.h"
#include "mmrtmImageDataConversion.h"
#include "mmrtmVtkSceneTranslation.h"

namespace mmrtm {
namespace {

// A float carries a value in [0, 1] to 6e-8; the tables are computed in
// double and stored as float. So 1e-6 absolute plus 1e-6 relative passes
// every correct table and fails a 1 % change of any value above 2e-4.
constexpr double kTableTolerance = 1e-6;

bool Near(double got, double expected, double tolerance = kTableTolerance) {
  return std::abs(got - expected) <= tolerance * (1.0 + std::abs(expected));
}

// The scene's TF named `where` (the translation names each table after its
// material and quantity, e.g. "volume scalar opacity").
const TransferFunctionDesc& Table(const Scene& scene, const std::string& where) {
  for (const TransferFunctionDesc& tf : scene.tfs)
    if (tf.where == where) return tf;
  ADD_FAILURE() << "no table '" << where << "'";
  static const TransferFunctionDesc none;
  return none;
}

const MaterialDesc& Material(const Scene& scene, const std::string& name) {
  const int index = scene.MaterialIndex(name);
  EXPECT_GE(index, 0) << "no material '" << name << "'";
  return scene.materials[std::max(index, 0)];
}

ProxyLayout ScalarLayout(float lo, float hi) {
  ProxyLayout layout;
  layout.scalarRange = {lo, hi};
  return layout;
}

Scene Translate(vtkVolumeProperty* property, const ProxyLayout& layout, const TranslationOptions& options = {}) {
  Scene scene;
  EXPECT_EQ(SetMaterialsFromProperty(property, 0, layout, options, scene), 0) << "no value should be replaced";
  return scene;
}

// The table is sampled at kTableSize evenly spaced values over `range`,
// both ends included: the values the checks below evaluate VTK at.
void ExpectPositionsOver(const TransferFunctionDesc& tf, std::array<float, 2> range) {
  ASSERT_EQ(tf.keys.size(), (size_t)kTableSize) << tf.where;
  EXPECT_EQ(tf.keys.front(), range[0]) << tf.where;
  EXPECT_EQ(tf.keys.back(), range[1]) << tf.where;
}

// sigma_t of opacity `alpha` per unit distance `unit`: a slab `unit` thick
// transmits 1 - alpha (VTK's opacity correction 1 - (1 - alpha)^(d / unit)).
double BeerLambertExtinction(double alpha, double unit) { return -std::log(1.0 - alpha) / unit; }

// Every value of an extinction table against -ln(1 - f(x)) / unit at its
// keys, and the values VTK's function takes there must include some well
// above 0 (so that the check has something to catch).
void ExpectExtinctionTable(const TransferFunctionDesc& tf, vtkPiecewiseFunction* f, double unit) {
  double largest = 0;
  for (size_t i = 0; i < tf.keys.size(); ++i) {
    const double expected = BeerLambertExtinction(f->GetValue(tf.keys[i]), unit);
    largest = std::max(largest, expected);
    ASSERT_TRUE(Near(tf.values[i], expected)) << tf.where << " at " << tf.keys[i] << ": sigma_t " << tf.values[i]
                                              << ", VTK's opacity per unit distance " << unit << " gives " << expected;
  }
  EXPECT_GT(largest, 0.1) << tf.where << ": the function is nearly empty, the check would catch nothing";
}

void ExpectColourTable(const TransferFunctionDesc& tf, vtkColorTransferFunction* f) {
  ASSERT_EQ(tf.channels, 3);
  for (size_t i = 0; i < tf.keys.size(); ++i) {
    double rgb[3];
    f->GetColor(tf.keys[i], rgb);
    for (int c = 0; c < 3; ++c)
      ASSERT_TRUE(Near(tf.values[3 * i + c], rgb[c])) << tf.where << " at " << tf.keys[i] << " channel " << c << ": "
                                                      << tf.values[3 * i + c] << ", VTK's GetColor " << rgb[c];
  }
}

// An opacity function whose first and last nodes lie inside [lo, hi] (so
// that the table holds values beyond them: clamped, or 0 without
// clamping), with midpoints and sharpness away from their defaults and a
// step.
vtkSmartPointer<vtkPiecewiseFunction> ShapedOpacity(double lo, double hi) {
  auto f = vtkSmartPointer<vtkPiecewiseFunction>::New();
  const double w = hi - lo;
  f->AddPoint(lo + 0.2 * w, 0.05, 0.3, 0.0);
  f->AddPoint(lo + 0.45 * w, 0.6, 0.7, 0.8);
  f->AddPoint(lo + 0.6 * w, 0.2, 0.5, 1.0);  // sharpness 1: a step at the midpoint
  f->AddPoint(lo + 0.85 * w, 0.9, 0.5, 0.0);
  return f;
}

vtkSmartPointer<vtkColorTransferFunction> ShapedColour(double lo, double hi) {
  auto f = vtkSmartPointer<vtkColorTransferFunction>::New();
  const double w = hi - lo;
  f->AddRGBPoint(lo + 0.1 * w, 0.9, 0.2, 0.1, 0.25, 0.0);
  f->AddRGBPoint(lo + 0.5 * w, 0.3, 0.8, 0.4, 0.6, 0.5);
  f->AddRGBPoint(lo + 0.8 * w, 0.2, 0.3, 1.0, 0.5, 1.0);
  return f;
}

// Scalar opacity per unit distance: each table value is VTK's opacity at
// the table's key as extinction, -ln(1 - alpha) / unit, to float precision:
// a 1 % change of sigma_t fails (tolerance 1e-6 relative), for clamping on
// and off.
TEST(VtkTranslation, ScalarOpacityIsExtinctionPerUnitDistance) {
  for (const bool clamping : {true, false}) {
    vtkNew<vtkVolumeProperty> property;
    auto opacity = ShapedOpacity(0, 1000);
    opacity->SetClamping(clamping);
    property->SetScalarOpacity(opacity);
    property->SetScalarOpacityUnitDistance(2.5);
    const Scene scene = Translate(property, ScalarLayout(0.f, 1000.f));
    const TransferFunctionDesc& tf = Table(scene, "volume scalar opacity");
    ExpectPositionsOver(tf, {0.f, 1000.f});
    // Some keys lie below the first node and above the last: clamping shows.
    ASSERT_LT(tf.keys[1], 200.f);
    ASSERT_GT(tf.keys[kTableSize - 2], 850.f);
    ExpectExtinctionTable(tf, opacity, 2.5);
  }
}

// The same for each independent component, with its own function and unit
// distance.
TEST(VtkTranslation, ScalarOpacityPerIndependentComponent) {
  vtkNew<vtkVolumeProperty> property;
  property->IndependentComponentsOn();
  const double units[2] = {0.5, 3.0};
  vtkSmartPointer<vtkPiecewiseFunction> opacity[2] = {ShapedOpacity(0, 255), ShapedOpacity(-100, 100)};
  for (int c = 0; c < 2; ++c) {
    property->SetScalarOpacity(c, opacity[c]);
    property->SetScalarOpacityUnitDistance(c, units[c]);
  }
  ProxyLayout layout = ScalarLayout(0.f, 255.f);
  layout.independent = 2;
  layout.componentRanges[0] = {0.f, 255.f};
  layout.componentRanges[1] = {-100.f, 100.f};
  const Scene scene = Translate(property, layout);
  ASSERT_TRUE(scene.additiveMaterials);
  for (int c = 0; c < 2; ++c) {
    const TransferFunctionDesc& tf = Table(scene, "component " + std::to_string(c) + " scalar opacity");
    EXPECT_EQ(tf.proxy, c);
    ExpectPositionsOver(tf, layout.componentRanges[c]);
    ExpectExtinctionTable(tf, opacity[c], units[c]);
  }
}

// A homogeneous slab of thickness d at opacity a per unit distance u
// transmits (1 - a)^(d / u): the tracer's shadow-ray estimator (ratio
// tracking) through the translated scene, 2,000,000 rays, checked by
// test::ExpectUnbiased (false failure below 7e-6). Its power, printed: a
// change of the transmittance by 1 % fails (with probability 1 - 1e-4); a
// 1 % change of sigma_t changes this slab's transmittance by 1.4 %.
TEST(VtkTranslation, HomogeneousSlabTransmitsBeerLambert) {
  vtkNew<vtkVolumeProperty> property;
  auto opacity = ShapedOpacity(0, 1000);
  property->SetScalarOpacity(opacity);
  const double unit = 2.5;
  property->SetScalarOpacityUnitDistance(unit);
  Scene scene = Translate(property, ScalarLayout(0.f, 1000.f));
  // The volume holds one of the table's keys, where the table is exact.
  const float value = Table(scene, "volume scalar opacity").keys[100];
  const double alpha = opacity->GetValue(value);
  ASSERT_GT(alpha, 0.3);
  // 33 voxels of spacing 0.5 (centres from 0 to 16 mm), crossed along x
  // from 2 to 7 mm: a slab 5 mm thick, away from the volume's rim (where
  // the values fade to the outside's).
  scene.proxies.push_back(test::MakeConstantVolume(33, value, 0.5f));
  const SceneView view = scene.Build();
  const Ray ray{{2.f, 8.f, 8.f}, {1.f, 0.f, 0.f}};
  const double thickness = 5.0;
  PCG32 rng(1, 2);
  TraceCounters counters;
  constexpr int kTrials = 2000000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < kTrials; ++i) {
    const double T = RatioTrack(view, ray, (float)thickness, 1.f, rng, counters);
    sum += T;
    sum2 += T * T;
  }
  const double mean = sum / kTrials, standardError = std::sqrt(std::max(sum2 / kTrials - mean * mean, 0.0) / kTrials);
  test::ExpectUnbiased(mean, standardError, std::pow(1.0 - alpha, thickness / unit),
                       "a slab 5 mm thick at opacity " + std::to_string(alpha) + " per 2.5 mm");
}

// Colour (RGB, with midpoints, sharpness, HSV interpolation, clamping on and
// off, and a log scale) and grey: each table value is VTK's GetColor or
// GetValue at the table's key, to float precision (tolerance 1e-6: a 1 %
// change of any channel above 2e-4 fails).
TEST(VtkTranslation, ColourTablesHoldVtksColours) {
  struct Case {
    const char* name;
    float lo, hi;
    bool clamping, hsv, log;
  };
  for (const Case c : {Case{"RGB, clamped", 0.f, 1000.f, true, false, false},
                       Case{"RGB, not clamped", 0.f, 1000.f, false, false, false},
                       Case{"HSV", -500.f, 500.f, true, true, false}, Case{"log10", 1.f, 1000.f, true, false, true}}) {
    SCOPED_TRACE(c.name);
    vtkNew<vtkVolumeProperty> property;
    auto colour = ShapedColour(c.lo, c.hi);
    colour->SetClamping(c.clamping);
    if (c.hsv) colour->SetColorSpaceToHSV();
    if (c.log) colour->SetScaleToLog10();
    property->SetColor(colour);
    property->ShadeOn();
    const Scene scene = Translate(property, ScalarLayout(c.lo, c.hi));
    const TransferFunctionDesc& tf = Table(scene, "volume color");
    ExpectPositionsOver(tf, {c.lo, c.hi});
    ExpectColourTable(tf, colour);
  }
  vtkNew<vtkVolumeProperty> property;
  vtkNew<vtkPiecewiseFunction> grey;
  grey->AddPoint(100, 0.1, 0.3, 0.2);
  grey->AddPoint(700, 0.8, 0.5, 0.0);
  property->SetColor(grey);
  const Scene scene = Translate(property, ScalarLayout(0.f, 1000.f));
  const TransferFunctionDesc& tf = Table(scene, "volume color");
  ExpectPositionsOver(tf, {0.f, 1000.f});
  for (size_t i = 0; i < tf.keys.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(Near(tf.values[3 * i + k], grey->GetValue(tf.keys[i]))) << "grey at " << tf.keys[i];
}

// The tracer reads the tables as they are: its own evaluation (the
// classifier's TF views after Scene::Build) at each key gives the table's
// value, to float precision.
TEST(VtkTranslation, TheTracerEvaluatesTheTablesAtTheirKeys) {
  vtkNew<vtkVolumeProperty> property;
  property->SetScalarOpacity(ShapedOpacity(0, 1000));
  property->SetColor(ShapedColour(0, 1000));
  Scene scene = Translate(property, ScalarLayout(0.f, 1000.f));
  scene.proxies.push_back(test::MakeConstantVolume(4, 500.f));
  const SceneView view = scene.Build();
  ASSERT_EQ(view.classifier.tfCount, (int)scene.tfs.size());
  for (const char* where : {"volume scalar opacity", "volume color"}) {
    const TransferFunctionDesc& tf = Table(scene, where);
    const TransferFunctionView& evaluated = view.classifier.tfs[&tf - scene.tfs.data()];
    for (size_t i = 0; i < tf.keys.size(); ++i) {
      float v[kMaxTFChannels];
      evaluated.Evaluate(tf.keys[i], v);
      for (int c = 0; c < tf.channels; ++c)
        ASSERT_TRUE(Near(v[c], tf.values[tf.channels * i + c])) << where << " at " << tf.keys[i];
    }
  }
}

// Gradient opacity: the table over the gradient-magnitude proxy's range
// holds VTK's GetValue at its keys, to float precision (a 1 % change of a
// value above 2e-4 fails), and multiplies the extinction.
TEST(VtkTranslation, GradientOpacityTableHoldsVtksValues) {
  vtkNew<vtkVolumeProperty> property;
  auto gradient = ShapedOpacity(0, 80);
  property->SetGradientOpacity(gradient);
  ASSERT_TRUE(UsesGradientOpacity(property, 0));
  ProxyLayout layout = ScalarLayout(0.f, 1000.f);
  layout.gradient = 1;
  layout.gradientRange = {0.f, 120.f};
  const Scene scene = Translate(property, layout);
  const TransferFunctionDesc& tf = Table(scene, "volume gradient opacity");
  EXPECT_EQ(tf.proxy, 1);
  ExpectPositionsOver(tf, layout.gradientRange);
  for (size_t i = 0; i < tf.keys.size(); ++i)
    ASSERT_TRUE(Near(tf.values[i], gradient->GetValue(tf.keys[i])))
        << "at gradient magnitude " << tf.keys[i] << ": " << tf.values[i] << ", VTK's GetValue "
        << gradient->GetValue(tf.keys[i]);
  bool multipliesDensity = false;
  for (const MaterialDesc::Binding& b : Material(scene, "volume").bindings)
    multipliesDensity |= b.tf == &tf - scene.tfs.data() && b.quantity == Quantity::Density;
  EXPECT_TRUE(multipliesDensity);
}

// The gradient-magnitude proxy is the magnitude of the gradient in world
// units, as vtkImageGradientMagnitude computes it (central differences over
// the spacing), for an anisotropic spacing and an oblique direction matrix
// (the magnitude does not depend on the rotation). Interior voxels, to
// 1e-5 relative: a 1 % change fails. The faces are not compared: there
// VTK's filter takes half the one-sided difference, the proxy the whole one.
TEST(VtkTranslation, GradientMagnitudeIsVtksInWorldUnits) {
  vtkNew<vtkImageData> image;
  const int n[3] = {12, 10, 8};
  image->SetDimensions(n[0], n[1], n[2]);
  image->SetSpacing(0.5, 1.25, 2.0);
  image->SetOrigin(-3, 4, 1);
  vtkNew<vtkMatrix3x3> direction;  // a rotation of 30 degrees about z
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const double rotation[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
  direction->DeepCopy(rotation);
  image->SetDirectionMatrix(direction);
  vtkNew<vtkFloatArray> values;
  values->SetNumberOfTuples((vtkIdType)n[0] * n[1] * n[2]);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        values->SetValue(i + n[0] * (j + n[1] * k), (float)(3.0 * i * i + 7.0 * j * k + 40.0 * std::sin(0.7 * k)));
  image->GetPointData()->SetScalars(values);

  const HostVolume scalars = ImageDataToHostVolume(image, values, 0, "scalars", Interpolation::Trilinear);
  const HostVolume proxy = GradientMagnitudeProxy(scalars, "gradient");
  vtkNew<vtkImageGradientMagnitude> vtk;
  vtk->SetInputData(image);
  vtk->SetDimensionality(3);
  vtk->HandleBoundariesOn();
  vtk->Update();
  vtkDataArray* expected = vtk->GetOutput()->GetPointData()->GetScalars();
  int compared = 0;
  for (int k = 1; k + 1 < n[2]; ++k)
    for (int j = 1; j + 1 < n[1]; ++j)
      for (int i = 1; i + 1 < n[0]; ++i) {
        const int64_t at = i + n[0] * (j + (int64_t)n[1] * k);
        const double want = expected->GetTuple1(at);
        ASSERT_TRUE(Near(proxy.Value(at), want, 1e-5))
            << "voxel (" << i << ", " << j << ", " << k << "): " << proxy.Value(at) << ", VTK " << want;
        ++compared;
      }
  EXPECT_EQ(compared, (n[0] - 2) * (n[1] - 2) * (n[2] - 2));
}

// Independent components: each component's colour times the square of its
// weight (scattered when shaded, glowing when not), weight 0 removes it;
// to float precision: a 1 % change of the factor fails.
TEST(VtkTranslation, ComponentWeightsScaleTheColourBySquare) {
  for (const bool shade : {true, false}) {
    vtkNew<vtkVolumeProperty> property;
    property->IndependentComponentsOn();
    property->SetShade(0, shade);
    property->SetShade(1, shade);
    property->SetShade(2, shade);
    const double weights[3] = {0.5, 0.8, 0.0};
    for (int c = 0; c < 3; ++c) property->SetComponentWeight(c, weights[c]);
    ProxyLayout layout = ScalarLayout(0.f, 255.f);
    layout.independent = 3;
    for (int c = 0; c < 3; ++c) layout.componentRanges[c] = {0.f, 255.f};
    const Scene scene = Translate(property, layout);
    const Quantity colour = shade ? Quantity::Albedo : Quantity::Emission;
    for (int c = 0; c < 3; ++c) {
      const MaterialDesc& m = Material(scene, "component " + std::to_string(c));
      for (int k = 0; k < 3; ++k)
        EXPECT_TRUE(Near(m.base[QuantityOffset(colour) + k], weights[c] * weights[c]))
            << "component " << c << (shade ? " albedo" : " emission") << " with weight " << weights[c] << ": "
            << m.base[QuantityOffset(colour) + k];
      EXPECT_EQ(m.base[QuantityOffset(Quantity::Density)], weights[c] > 0 ? 1.f : 0.f);
    }
  }
}

// Dependent components, RGBA: the albedo is the colour components
// themselves (unsigned char over 255) and the opacity component goes
// through the scalar-opacity function; evaluated by the tracer's classifier
// on constant volumes, to float precision (a 1 % change of the colour
// scale or of sigma_t fails).
TEST(VtkTranslation, DependentRgbaIsTheColourAndTheOpacityComponent) {
  vtkNew<vtkVolumeProperty> property;
  property->IndependentComponentsOff();
  property->ShadeOn();
  auto opacity = ShapedOpacity(0, 255);
  property->SetScalarOpacity(opacity);
  property->SetScalarOpacityUnitDistance(2.0);
  const float rgba[4] = {51.f, 102.f, 204.f, 120.f};
  Scene scene;
  for (int c = 0; c < 4; ++c) scene.proxies.push_back(test::MakeConstantVolume(4, rgba[c]));
  ProxyLayout layout = ScalarLayout(rgba[0], rgba[0]);
  layout.rgb[0] = 0, layout.rgb[1] = 1, layout.rgb[2] = 2;
  layout.opacity = 3;
  layout.opacityRange = {rgba[3], rgba[3]};
  layout.colorScale = 255.f;
  ASSERT_EQ(SetMaterialsFromProperty(property, 0, layout, {}, scene), 0);
  const SceneView view = scene.Build();
  const Vec3 centre = scene.proxies[0].WorldCenter();
  const Classification c = view.classifier.Classify(centre);
  const MaterialCoefficients k = view.classifier.Coefficients(c);
  EXPECT_TRUE(Near(k.albedo.r, rgba[0] / 255.0) && Near(k.albedo.g, rgba[1] / 255.0) &&
              Near(k.albedo.b, rgba[2] / 255.0))
      << "albedo (" << k.albedo.r << ", " << k.albedo.g << ", " << k.albedo.b << ")";
  const double sigma = BeerLambertExtinction(opacity->GetValue(rgba[3]), 2.0);
  ASSERT_GT(sigma, 0.05);
  EXPECT_TRUE(Near(c.sigma_t, sigma)) << "sigma_t " << c.sigma_t << ", VTK's opacity gives " << sigma;
}

// Dependent components, LA: component 0 through the colour function,
// component 1 (its own range) through the scalar-opacity function.
TEST(VtkTranslation, DependentLaIsColourAndOpacity) {
  vtkNew<vtkVolumeProperty> property;
  property->IndependentComponentsOff();
  auto opacity = ShapedOpacity(0, 200);
  auto colour = ShapedColour(0, 1000);
  property->SetScalarOpacity(opacity);
  property->SetColor(colour);
  ProxyLayout layout = ScalarLayout(0.f, 1000.f);
  layout.opacity = 1;
  layout.opacityRange = {0.f, 200.f};
  const Scene scene = Translate(property, layout);
  const TransferFunctionDesc& a = Table(scene, "volume scalar opacity");
  EXPECT_EQ(a.proxy, 1);
  ExpectPositionsOver(a, layout.opacityRange);
  ExpectExtinctionTable(a, opacity, 1.0);
  const TransferFunctionDesc& l = Table(scene, "volume color");
  EXPECT_EQ(l.proxy, 0);
  ExpectPositionsOver(l, layout.scalarRange);
  ExpectColourTable(l, colour);
}

// A label map with per-label functions: a label with its own opacity and
// colour is classified by them, a label with a colour only by its colour and
// the component's opacity, label 0 by the component's functions; checked in
// the tables (to float precision: a 1 % change of sigma_t fails) and by the
// tracer's classifier on constant volumes.
TEST(VtkTranslation, LabelFunctionsClassifyTheirLabels) {
  vtkNew<vtkVolumeProperty> property;
  auto opacity = ShapedOpacity(0, 1000);
  auto labelOpacity = ShapedOpacity(-200, 900);
  auto labelColour = ShapedColour(300, 1000);
  auto otherColour = ShapedColour(0, 500);
  property->SetScalarOpacity(opacity);
  property->SetScalarOpacityUnitDistance(1.5);
  property->SetLabelScalarOpacity(1, labelOpacity);
  property->SetLabelColor(1, labelColour);
  property->SetLabelColor(2, otherColour);
  ProxyLayout layout = ScalarLayout(0.f, 1000.f);
  layout.labels = 1;
  Scene scene = Translate(property, layout);
  ExpectExtinctionTable(Table(scene, "label 1 scalar opacity"), labelOpacity, 1.5);
  ExpectColourTable(Table(scene, "label 1 color"), labelColour);
  ExpectExtinctionTable(Table(scene, "label 2 scalar opacity"), opacity, 1.5);
  ExpectColourTable(Table(scene, "label 2 color"), otherColour);
  ExpectExtinctionTable(Table(scene, "volume scalar opacity"), opacity, 1.5);

  const float value = Table(scene, "label 1 scalar opacity").keys[150];
  scene.proxies.push_back(test::MakeConstantVolume(4, value));
  for (const int label : {0, 1, 2}) {
    scene.proxies.resize(1);
    scene.proxies.push_back(test::MakeConstantVolume(4, (float)label));
    scene.proxies.back().interpolation = Interpolation::Nearest;
    const SceneView view = scene.Build();
    const Classification c = view.classifier.Classify(scene.proxies[0].WorldCenter());
    vtkPiecewiseFunction* f = label == 1 ? labelOpacity.Get() : opacity.Get();
    const double sigma = BeerLambertExtinction(f->GetValue(value), 1.5);
    ASSERT_GT(sigma, 0.05);
    EXPECT_TRUE(Near(c.sigma_t, sigma)) << "label " << label << ": sigma_t " << c.sigma_t << ", VTK " << sigma;
    EXPECT_EQ(c.material,
              label == 0 ? scene.MaterialIndex("volume") : scene.MaterialIndex("label " + std::to_string(label)));
  }
}

// SetLabelMaterial (the one label rule, LabelMaterial): opacity 1 is an
// extinction of kLabelDensityAtFullOpacity per mm, opacity a that times a,
// the colour the albedo; exact to float precision (a 1 % change fails),
// in the material and in the tracer's classifier.
TEST(VtkTranslation, LabelMaterialAtFullOpacity) {
  vtkNew<vtkVolumeProperty> property;
  property->ShadeOn();
  ProxyLayout layout = ScalarLayout(0.f, 1000.f);
  layout.labels = 1;
  Scene scene = Translate(property, layout);
  LabelLook full;
  full.color = {0.2, 0.5, 0.9};
  full.opacity = 1.0;
  SetLabelLook(3, full, property, 0, layout, {}, scene);
  LabelLook part = full;
  part.opacity = 0.4;
  SetLabelLook(4, part, property, 0, layout, {}, scene);
  for (const auto& [label, look] : {std::pair<int, LabelLook>{3, full}, {4, part}}) {
    const MaterialDesc& m = Material(scene, "label " + std::to_string(label));
    EXPECT_TRUE(Near(m.base[QuantityOffset(Quantity::Density)], kLabelDensityAtFullOpacity * look.opacity))
        << "label " << label << " at opacity " << look.opacity << ": " << m.base[QuantityOffset(Quantity::Density)];
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(Near(m.base[QuantityOffset(Quantity::Albedo) + k], look.color[k]));
  }
  scene.proxies.push_back(test::MakeConstantVolume(4, 500.f));
  scene.proxies.push_back(test::MakeConstantVolume(4, 3.f));
  scene.proxies.back().interpolation = Interpolation::Nearest;
  const SceneView view = scene.Build();
  EXPECT_TRUE(Near(view.classifier.Classify(scene.proxies[0].WorldCenter()).sigma_t, kLabelDensityAtFullOpacity));
}

// Shading parameters that map: Ambient is the radiance of a constant
// environment; Diffuse scales each light to irradiance
// pi x intensity x colour x Diffuse (a positional light's at its focal
// point); SpecularPower p gives roughness (2 / (p + 2))^(1/4) where
// Specular is above 0, 1 where it is 0; Shade gives surface scattering.
// To float precision: a 1 % change of any fails.
TEST(VtkTranslation, ShadingParametersThatMap) {
  vtkNew<vtkVolumeProperty> property;
  property->ShadeOn();
  property->SetAmbient(0.3);
  property->SetDiffuse(0.6);
  property->SetSpecular(0.5);
  property->SetSpecularPower(30.0);
  const Scene scene = Translate(property, ScalarLayout(0.f, 1000.f));
  const MaterialDesc& m = Material(scene, "volume");
  EXPECT_TRUE(Near(m.base[QuantityOffset(Quantity::Roughness)], std::pow(2.0 / 32.0, 0.25)))
      << "roughness " << m.base[QuantityOffset(Quantity::Roughness)];
  EXPECT_EQ(m.base[QuantityOffset(Quantity::SurfaceProbability)], kShadedSurfaceProbability);
  property->SetSpecular(0.0);
  EXPECT_EQ(
      Material(Translate(property, ScalarLayout(0.f, 1000.f)), "volume").base[QuantityOffset(Quantity::Roughness)],
      1.f);

  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkLight> sun, lamp;
  sun->SetLightTypeToSceneLight();
  sun->PositionalOff();
  sun->SetPosition(1, 2, 3);
  sun->SetFocalPoint(0, 0, 0);
  sun->SetIntensity(0.7);
  sun->SetDiffuseColor(1.0, 0.8, 0.6);
  lamp->SetLightTypeToSceneLight();
  lamp->PositionalOn();
  lamp->SetPosition(0, 0, 10);
  lamp->SetFocalPoint(0, 0, 4);
  lamp->SetIntensity(0.5);
  lamp->SetDiffuseColor(0.2, 0.4, 1.0);
  renderer->AddLight(sun);
  renderer->AddLight(lamp);
  Scene lit;
  SetLightsFromVtk(renderer, property, lit);
  ASSERT_EQ(lit.lights.size(), 2u);
  const double diffuse = 0.6;
  const double sunColour[3] = {1.0, 0.8, 0.6}, lampColour[3] = {0.2, 0.4, 1.0};
  const float sunL[3] = {lit.lights[0].L.r, lit.lights[0].L.g, lit.lights[0].L.b};
  const float lampL[3] = {lit.lights[1].L.r, lit.lights[1].L.g, lit.lights[1].L.b};
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(Near(sunL[c], M_PI * 0.7 * sunColour[c] * diffuse))
        << "directional light, channel " << c << ": " << sunL[c] << " for " << M_PI * 0.7 * sunColour[c] * diffuse;
    EXPECT_TRUE(Near(lampL[c], M_PI * 0.5 * lampColour[c] * diffuse * 36.0))
        << "positional light 6 mm from its focal point, channel " << c << ": " << lampL[c] << " for "
        << M_PI * 0.5 * lampColour[c] * diffuse * 36.0;
  }
  ASSERT_TRUE(lit.environment);
  for (const RGB& texel : lit.environment->Texels())
    ASSERT_TRUE(Near(texel.r, 0.3) && Near(texel.g, 0.3) && Near(texel.b, 0.3))
        << "ambient radiance " << texel.r << ", " << texel.g << ", " << texel.b;
}

// Parameters that do not map (Documentation/vtk-mapper.md names them):
// Specular's size beyond whether it is 0, and InterpolationType, change
// nothing in the scene.
TEST(VtkTranslation, ShadingParametersThatDoNotMapChangeNothing) {
  auto translate = [](double specular, int interpolation) {
    vtkNew<vtkVolumeProperty> property;
    property->ShadeOn();
    property->SetScalarOpacity(ShapedOpacity(0, 1000));
    property->SetColor(ShapedColour(0, 1000));
    property->SetSpecular(specular);
    property->SetInterpolationType(interpolation);
    return Translate(property, ScalarLayout(0.f, 1000.f));
  };
  const Scene a = translate(0.2, VTK_NEAREST_INTERPOLATION), b = translate(0.9, VTK_LINEAR_INTERPOLATION);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t m = 0; m < a.materials.size(); ++m)
    for (int k = 0; k < kCoefficientFloats; ++k) EXPECT_EQ(a.materials[m].base[k], b.materials[m].base[k]);
  ASSERT_EQ(a.tfs.size(), b.tfs.size());
  for (size_t t = 0; t < a.tfs.size(); ++t) EXPECT_EQ(a.tfs[t].values, b.tfs[t].values) << a.tfs[t].where;
}

}  // namespace
}  // namespace mmrtm
