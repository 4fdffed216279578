// Reading the mapper's inputs into one record, comparing it with the
// record the scene was made from, and updating the proxies, the
// description and the materials as far as they changed.
#include "vtkMultiMaterialVolumeMapperInternals.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <vtkDataArray.h>
#include <vtkColorTransferFunction.h>
#include <vtkContourValues.h>
#include <vtkPiecewiseFunction.h>
#include <vtkRenderer.h>
#include <vtkRectilinearGrid.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>

#include "mmrtmVolumePropertyFunctions.h"
#include "mmrtm/planted_defect.h"

namespace
{
// The property's modification time without the edits of its colour
// functions: what the planted defect MapperColorRefit sees.
vtkMTimeType MTimeWithoutColours(vtkVolumeProperty* p)
{
  vtkMTimeType t = p->vtkObject::GetMTime();
  for (int c = 0; c < VTK_MAX_VRCOMP; ++c)
    for (vtkPiecewiseFunction* f : { mmrtm::HeldScalarOpacity(p, c), mmrtm::HeldGradientOpacity(p, c) })
      if (f)
        t = std::max(t, f->GetMTime());
  return t;
}

// The latest modification among the property and its functions.
// vtkVolumeProperty::GetMTime counts the component functions it holds and
// when label functions were set; a label function edited in place is
// counted here. Nothing is created in the property (its getters would).
vtkMTimeType PropertyMTime(vtkVolumeProperty* p)
{
  const bool missColours = mmrtm::Planted(mmrtm::Defect::MapperColorRefit);
  vtkMTimeType t = missColours ? MTimeWithoutColours(p) : p->GetMTime();
  if (vtkImageData* table = p->GetTransferFunction2D(0))
    t = std::max(t, table->GetMTime());
  for (const vtkTimeStamp& set :
    { p->GetLabelColorMTime(), p->GetLabelScalarOpacityMTime(), p->GetLabelGradientOpacityMTime() })
    t = std::max(t, set.GetMTime());
  for (int label : p->GetLabelMapLabels())
  {
    if (vtkPiecewiseFunction* f = p->GetLabelScalarOpacity(label))
      t = std::max(t, f->GetMTime());
    if (vtkPiecewiseFunction* f = p->GetLabelGradientOpacity(label))
      t = std::max(t, f->GetMTime());
    if (vtkColorTransferFunction* f = p->GetLabelColor(label))
      t = std::max(t, missColours ? 0 : f->GetMTime());
  }
  return t;
}
}

bool vtkMultiMaterialVolumeMapper::Internals::ValidateInputs(vtkRenderer* ren, vtkVolume* vol, int viewport[4])
{
  Internals& in = *this;
  if (!Self->GetInput() || !vol->GetProperty())
  {
    vtkErrorWithObjectMacro(
      Self, "Render: " << (Self->GetInput() ? "the vtkVolume has no volume property" : "no input"));
    return false;
  }
  ren->GetTiledSizeAndOrigin(&viewport[0], &viewport[1], &viewport[2], &viewport[3]);
  return viewport[0] > 0 && viewport[1] > 0;
}

vtkMultiMaterialVolumeMapper::Internals::InputState vtkMultiMaterialVolumeMapper::Internals::ReadInputs(
  vtkRenderer* ren, vtkVolume* vol, const int viewport[4])
{
  Internals& in = *this;
  InputState now;
  // The input brought up to date (a new or modified input rebuilds).
  Self->GetInputAlgorithm()->UpdateInformation();
  Self->GetInputAlgorithm()->Update();
  this->ReadTracedImage(now);
  now.Proxies.Mask = in.Mask;
  now.Proxies.MaskTime = in.Mask ? in.Mask->GetMTime() : 0;
  now.Proxies.MaskType = Self->MaskType;
  now.Proxies.MultiMaterial = in.MultiMaterial;

  // The proxies the property asks for.
  vtkVolumeProperty* property = vol->GetProperty();
  const int components = now.Proxies.Scalars->GetNumberOfComponents();
  const bool independent = property->GetIndependentComponents() != 0;
  now.Proxies.Dependent = !independent && (components == 2 || components == 4) ? components : 0;
  now.Proxies.Independent = independent && components > 1 ? std::min(components, 4) : 0;
  // 4 dependent components fill the 4 proxies: no room for a gradient.
  const bool labels = in.Mask && Self->MaskType == LABELMAP;
  // Isosurfaces of one component (the others render as composite).
  const bool isosurface = Self->BlendMode == vtkVolumeMapper::ISOSURFACE_BLEND && !in.MultiMaterial;
  const bool isosurfaceComponents = isosurface && (now.Proxies.Dependent || now.Proxies.Independent);
  if (in.Warn("isosurface with components", isosurfaceComponents))
    vtkWarningWithObjectMacro(Self,
      "isosurface blending of " << components << " components is not supported; rendering as composite");
  now.Materials.Options.isosurface = isosurface && !isosurfaceComponents;
  if (now.Materials.Options.isosurface)
  {
    vtkContourValues* values = property->GetIsoSurfaceValues();
    for (int i = 0; i < values->GetNumberOfContours(); ++i)
      now.Materials.Options.isoValues.push_back(values->GetValue(i));
    // VTK's GPU mapper composites an iso-value's opacity once per crossing,
    // corrected from the unit distance to its sample distance: the
    // smallest voxel spacing, or SampleDistance when the distances do not
    // adapt.
    const double* spacing = now.Proxies.Data->GetSpacing();
    now.Materials.Options.isoSampleDistance = !Self->AutoAdjustSampleDistances && Self->SampleDistance > 0.f
      ? Self->SampleDistance
      : static_cast<float>(std::min({ std::abs(spacing[0]), std::abs(spacing[1]), std::abs(spacing[2]) }));
  }
  // The projections show the colour they read as the albedo.
  const bool projection = Self->BlendMode == vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND ||
    Self->BlendMode == vtkVolumeMapper::MINIMUM_INTENSITY_BLEND ||
    Self->BlendMode == vtkVolumeMapper::AVERAGE_INTENSITY_BLEND || Self->BlendMode == vtkVolumeMapper::ADDITIVE_BLEND;
  now.Materials.Options.unshadedScatters = Self->UnshadedScattering || projection;
  now.Materials.Options.localLighting = !Self->GlobalIllumination;
  now.Proxies.NeedGradient = !in.MultiMaterial && now.Proxies.Dependent != 4 && !now.Proxies.Independent &&
    (mmrtm::NeedsGradientProxy(property, 0, labels) || now.Materials.Options.isosurface);
  now.Proxies.ComponentGradients = 0;
  for (int c = 0; c < now.Proxies.Independent; ++c)
    now.Proxies.ComponentGradients |= mmrtm::UsesGradientOpacity(property, c) ? 1 << c : 0;
  if (in.Warn("components", components > 4 && now.Proxies.Independent))
    vtkWarningWithObjectMacro(Self, "only the first 4 of " << components << " independent components are rendered");
  if (in.Warn("mask with components", now.Proxies.Independent && in.Mask))
    vtkWarningWithObjectMacro(Self, "with independent components, the mask is not used");

  now.Materials.Property = property;
  now.Materials.PropertyTime = PropertyMTime(property);
  now.Materials.MultiMaterialTime = in.MultiMaterial ? in.MultiMaterial->GetMTime() : 0;
  now.Materials.LabelMaterialsTime = in.LabelMaterialsTime();

  this->ReadView(ren, vol, viewport, now.View);
  return now;
}

void vtkMultiMaterialVolumeMapper::Internals::ReadTracedImage(InputState& now)
{
  // The input as the tracer's image (mmrtmTracedImage.h), converted again
  // only when the input, its scalars or their modification times changed,
  // so that an unchanged input does not rebuild.
  Internals& in = *this;
  vtkDataSet* input = Self->GetInput();
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(
    input, Self->ScalarMode, Self->ArrayAccessMode, Self->ArrayId, Self->ArrayName, cellFlag);
  if (!scalars)
    throw mmrtm::InputError(
      std::string("the input (a ") + input->GetClassName() + ") has no scalars for the mapper's scalar mode");
  Internals::Conversion& c = in.Converted;
  const vtkMTimeType inputTime = input->GetMTime(), scalarsTime = scalars->GetMTime();
  if (c.Input != input || c.InputTime != inputTime || c.Scalars != scalars || c.ScalarsTime != scalarsTime ||
    c.Cell != (cellFlag != 0))
  {
    c = Internals::Conversion{};
    c.Traced = mmrtm::ImageForTracing(input, scalars, cellFlag != 0);
    c.Input = input;
    c.InputTime = inputTime;
    c.Scalars = scalars;
    c.ScalarsTime = scalarsTime;
    c.Cell = cellFlag != 0;
  }
  now.Proxies.Data = c.Traced.Image ? c.Traced.Image.Get() : vtkImageData::SafeDownCast(input);
  now.Proxies.DataTime = inputTime;
  now.Proxies.Scalars = c.Traced.Image ? c.Traced.Scalars : scalars;
  const bool resampled = vtkRectilinearGrid::SafeDownCast(input) != nullptr;
  if (in.Warn("rectilinear grid", resampled))
    vtkWarningWithObjectMacro(
      Self, << c.Traced.Conversion << " (VTK's GPU mapper samples the grid on its own coordinates)");
}

vtkMultiMaterialVolumeMapper::Internals::Changes vtkMultiMaterialVolumeMapper::Internals::ChangesSince(
  const InputState& built, const InputState& now)
{
  Changes c;
  c.Proxies = !this->HasScene || !(now.Proxies == built.Proxies);
  const bool description = now.Proxies.MultiMaterial != nullptr;
  c.Description = description &&
    (now.Materials.MultiMaterialTime != built.Materials.MultiMaterialTime ||
      now.Materials.LabelMaterialsTime != built.Materials.LabelMaterialsTime);
  c.Materials = !description &&
    (now.Materials.Property != built.Materials.Property || now.Materials.PropertyTime != built.Materials.PropertyTime ||
      now.Materials.LabelMaterialsTime != built.Materials.LabelMaterialsTime ||
      !(now.Materials.Options == built.Materials.Options));
  c.View = !SameViewInputs(now.View, built.View);
  return c;
}

void vtkMultiMaterialVolumeMapper::Internals::UpdateProxies(const InputState& now)
{
  Internals& in = *this;
  in.HasScene = false; // until the rebuild succeeds
  const bool labels = now.Proxies.Mask && now.Proxies.MaskType == LABELMAP;
  const InputState::ProxyInputs& p = now.Proxies;
  in.ImageIndexToWorld.clear();
  in.Layout = mmrtm::BuildProxies(now.Materials.Property, p.Data, p.Scalars, p.Independent ? nullptr : in.Mask.Get(),
    p.Dependent, p.Independent, p.NeedGradient, labels, in.Scene,
    [&](const std::string& warning) { vtkWarningWithObjectMacro(Self, << warning); });
  int64_t nans = 0;
  for (const mmrtm::HostVolume& v : in.Scene.proxies)
    nans += v.nanVoxelsReplaced;
  if (in.Warn("NaN voxels", nans > 0))
    vtkWarningWithObjectMacro(Self, << nans
                    << " voxel value(s) of the input or mask are NaN; they are rendered as the volume's least "
                       "value (empty where its opacity is 0)");
  in.LightsFromScene = false;
  if (now.Proxies.MultiMaterial)
    this->ParseMultiMaterialScene();
  for (const mmrtm::HostVolume& v : in.Scene.proxies)
    in.ImageIndexToWorld.push_back(v.indexToWorld);
  in.Scene.MarkDataModified();
  in.Built.Proxies = now.Proxies;
  in.Built.Materials.MultiMaterialTime = now.Materials.MultiMaterialTime; // parsed over them
  in.Built.Materials.LabelMaterialsTime = now.Materials.LabelMaterialsTime;
  ++in.SceneBuilds;
}

void vtkMultiMaterialVolumeMapper::Internals::ParseMultiMaterialScene()
{
  // The description over the mapper's volumes: its input as "scalars" (and
  // the mask as "labels"); the camera and image size stay VTK's. The
  // labels' looks (SetLabelMaterial) are classes of the description's
  // label materials, ahead of its own.
  Internals& in = *this;
  nlohmann::json doc = in.MultiMaterial->GetScene();
  doc.erase("camera");
  doc.erase("volumes"); // a description's own files are not the mapper's data
  if (in.Layout.labels >= 0)
    doc = mmrtm::WithLabelLooks(std::move(doc), in.LabelLooksWithParameters());
  mmrtm::SceneInputs inputs;
  mmrtm::ExpandLabelMaterialsOnLoad(inputs);
  inputs.volumes["scalars"] = std::move(in.Scene.proxies[0]);
  for (size_t i = 1; i < in.Scene.proxies.size(); ++i)
    if (static_cast<int>(i) == in.Layout.labels || static_cast<int>(i) == in.Layout.binaryMask)
      inputs.volumes["labels"] = std::move(in.Scene.proxies[i]);
  in.LightsFromScene = doc.contains("lights");
  in.Scene = mmrtm::SceneFromJson(doc, std::move(inputs));
  const std::array<float, 2> range = in.Layout.scalarRange; // the input's, for the projections
  in.Layout = mmrtm::ProxyLayout();
  in.Layout.scalarRange = range;
  ++in.Refits;
}

void vtkMultiMaterialVolumeMapper::Internals::ReparseMultiMaterialScene()
{
  // The description is parsed over the proxies of the last build (the
  // input and the mask, moved with their buffers and given back their own
  // index-to-world: the volume's matrix is applied at the restart). The
  // grid's summaries go over to the new scene when its proxies are those
  // very buffers, so that the edit costs a refit.
  Internals& in = *this;
  in.HasScene = false; // until the parse succeeds; after a failure the input is read again
  mmrtm::Scene previous = std::move(in.Scene);
  in.Scene = mmrtm::Scene();
  const std::array<float, 2> range = in.Layout.scalarRange; // the input's, for the projections
  in.Layout = mmrtm::ProxyLayout();
  in.Layout.scalarRange = range;
  const int labels = previous.ProxyIndex("labels");
  for (const int i : { 0, labels })
  {
    if (i < 0 || i >= static_cast<int>(previous.proxies.size()))
      continue;
    mmrtm::HostVolume volume = std::move(previous.proxies[i]);
    volume.indexToWorld = in.ImageIndexToWorld.at(i);
    if (i == labels)
      in.Layout.labels = static_cast<int>(in.Scene.proxies.size());
    in.Scene.proxies.push_back(std::move(volume));
  }
  this->ParseMultiMaterialScene();
  in.Scene.AdoptDataSummariesFrom(previous);
  in.ImageIndexToWorld.clear();
  for (const mmrtm::HostVolume& v : in.Scene.proxies)
    in.ImageIndexToWorld.push_back(v.indexToWorld);
  in.HasScene = true;
}

void vtkMultiMaterialVolumeMapper::Internals::UpdateDescription(const InputState& now)
{
  // An edited description over unchanged data: parsed again over the
  // proxies as they are, and refitted.
  this->ReparseMultiMaterialScene();
  this->Built.Materials.MultiMaterialTime = now.Materials.MultiMaterialTime;
  this->Built.Materials.LabelMaterialsTime = now.Materials.LabelMaterialsTime;
}

void vtkMultiMaterialVolumeMapper::Internals::UpdateMaterials(const InputState& now)
{
  // The transfer functions translated again (the scene's build refits).
  Internals& in = *this;
  if (const int nonFinite =
        mmrtm::SetMaterialsFromProperty(now.Materials.Property, 0, in.Layout, now.Materials.Options, in.Scene))
    vtkWarningWithObjectMacro(Self, << "the volume property holds " << nonFinite
                    << " value(s) that are not finite (NaN in a transfer function or a component "
                       "weight); they were read as 0");
  if (in.Layout.labels >= 0)
  {
    for (const auto& [label, look] : in.LabelLooks)
      mmrtm::SetLabelLook(label, look, now.Materials.Property, 0, in.Layout, now.Materials.Options, in.Scene);
    for (const auto& [label, json] : in.LabelMaterialParameters)
      mmrtm::SetLabelMaterialParameters(label, json, in.Scene);
  }
  in.Built.Materials = now.Materials;
  ++in.Refits;
}

void vtkMultiMaterialVolumeMapper::Internals::UpdateRenderer()
{
  Internals& in = *this;
  if (in.Renderer && in.RendererBackend == Self->Backend && in.RendererThreads == Self->NumberOfThreads)
    return;
  const mmrtm::Backend backend = Self->Backend == CPU ? mmrtm::Backend::Cpu
    : Self->Backend == CUDA                           ? mmrtm::Backend::Cuda
                                                      : mmrtm::Backend::Auto;
  in.Renderer = mmrtm::MakeRenderer(
    backend, Self->NumberOfThreads, [this](const std::string& note) { vtkDebugWithObjectMacro(Self, << note); });
  in.RendererBackend = Self->Backend;
  in.RendererThreads = Self->NumberOfThreads;
  in.BackendDescription = in.Renderer->Description();
}

mmrtm::SceneView vtkMultiMaterialVolumeMapper::Internals::BuildScene()
{
  // A new volume's summary build reads every voxel (14 s for 8 GiB on two
  // cores): VTK's ProgressEvent tells the application, on this thread.
  mmrtm::Scene& scene = this->Scene;
  scene.buildProgress = [this](double fraction) { Self->UpdateProgress(fraction); };
  return scene.Build();
}
