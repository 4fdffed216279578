#include "vtkMultiMaterialVolumeMapper.h"
#include "vtkMultiMaterialVolumeMapperInternals.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkInformation.h>
#include <vtkInformationObjectBaseVectorKey.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLRenderPass.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkVolume.h>
#if __has_include(<vtk_glad.h>)
#include <vtk_glad.h> // VTK 9.4 and later: the GL enums
#else
#include <vtk_glew.h>
#endif

#include "mmrtmImageDataConversion.h"

vtkStandardNewMacro(vtkMultiMaterialVolumeMapper);

namespace
{
// Equal to the bit, NaN to NaN: a setting set again to its value is no change.
bool SameValues(const std::vector<double>& a, const std::vector<double>& b)
{
  return a.size() == b.size() &&
    std::equal(a.begin(), a.end(), b.begin(),
      [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); });
}

// What the traced image depends on in the mapper itself, as values
// (GetTracingMTime compares them): the settings that ReadInputs,
// UpdateView, Projection, CroppingRegions and UpdateEnvironment read (the
// scalar array's name is compared where the input is converted), the
// backend (a CPU and a CUDA film are not mixed), the clipping planes, and
// the modification times of the objects the mapper holds (`held`: each a
// tick of VTK's global clock, so another object is another time). Not
// among them: the drawing's settings and the refinement's, which keep the
// samples, and the image sample distances, which decide the film's size
// (compared with the view) and the previews'.
std::vector<double> TracingInputs(vtkMultiMaterialVolumeMapper* m, std::initializer_list<vtkMTimeType> held)
{
  std::vector<double> v = { static_cast<double>(m->GetSeed()), static_cast<double>(m->GetBackend()),
    static_cast<double>(m->GetGlobalIllumination()), m->GetShadowExtinctionScale(),
    static_cast<double>(m->GetMaximumBounces()), static_cast<double>(m->GetSampler()),
    static_cast<double>(m->GetAccelerator()), static_cast<double>(m->GetUnshadedScattering()),
    static_cast<double>(m->GetBlendMode()), static_cast<double>(m->GetAutoAdjustSampleDistances()),
    m->GetSampleDistance(), m->GetAverageIPScalarRange()[0], m->GetAverageIPScalarRange()[1],
    static_cast<double>(m->GetMaskType()),
    m->GetEnvironmentIntensity(), static_cast<double>(m->GetScalarMode()),
    static_cast<double>(m->GetArrayAccessMode()), static_cast<double>(m->GetArrayId()),
    static_cast<double>(m->GetCropping()), static_cast<double>(m->GetCroppingRegionFlags()) };
  const double* crop = m->GetCroppingRegionPlanes();
  v.insert(v.end(), crop, crop + 6);
  if (vtkPlaneCollection* planes = m->GetClippingPlanes())
    for (int i = 0; i < planes->GetNumberOfItems(); ++i)
    {
      vtkPlane* plane = planes->GetItem(i);
      v.insert(v.end(), plane->GetOrigin(), plane->GetOrigin() + 3);
      v.insert(v.end(), plane->GetNormal(), plane->GetNormal() + 3);
    }
  for (vtkMTimeType t : held)
    v.push_back(static_cast<double>(t));
  return v;
}
}

vtkMultiMaterialVolumeMapper::vtkMultiMaterialVolumeMapper()
  : Internal(new Internals(this))
{
}

vtkMultiMaterialVolumeMapper::~vtkMultiMaterialVolumeMapper()
{
  this->Internal->FinishPass(true);
  for (const auto& frame : this->Internal->PeelFrames)
    if (vtkRenderer* ren = frame->Renderer)
      ren->RemoveObserver(frame->Observer);
}

bool vtkMultiMaterialVolumeMapper::IsRefining()
{
  return this->Internal->InFlight && !this->Internal->InFlight->Done;
}

void vtkMultiMaterialVolumeMapper::ResetAccumulation()
{
  this->Internal->FinishPass(true);
  if (this->Internal->Film)
    this->Internal->Film->Reset();
  ++this->Internal->FilmGeneration;
}

void vtkMultiMaterialVolumeMapper::SetDenoisingMode(int mode)
{
  mode = std::clamp(mode, static_cast<int>(DENOISING_OFF), static_cast<int>(DENOISING_ALWAYS));
  if (mode == this->DenoisingMode)
    return;
  this->DenoisingMode = mode;
  this->Internal->Display.SetMode(mode == DENOISING_AUTO ? mmrtm::DenoisingMode::Auto
      : mode == DENOISING_ALWAYS                         ? mmrtm::DenoisingMode::Always
                                                         : mmrtm::DenoisingMode::Off);
  this->Modified();
}

void vtkMultiMaterialVolumeMapper::SetLookToVTK()
{
  this->SetToneMappingToAutomatic();
  this->SetUnshadedScattering(0);
}

void vtkMultiMaterialVolumeMapper::SetLookToFilmic()
{
  this->SetToneMappingToFilmic();
  this->SetUnshadedScattering(1);
}

vtkMTimeType vtkMultiMaterialVolumeMapper::GetTracingMTime()
{
  Internals& in = *this->Internal;
  vtkTexture* environment = in.EnvironmentTexture;
  const std::vector<double> now = TracingInputs(this,
    { in.Mask ? in.Mask->GetMTime() : 0, in.MultiMaterial ? in.MultiMaterial->GetMTime() : 0,
      in.LabelMaterialsTime(), environment ? environment->GetMTime() : 0,
      environment && environment->GetInput() ? environment->GetInput()->GetMTime() : 0 });
  if (!SameValues(now, in.TracingInputsSeen))
  {
    in.TracingInputsSeen = now;
    in.TracingInputsTime.Modified();
  }
  return in.TracingInputsTime.GetMTime();
}

void vtkMultiMaterialVolumeMapper::SetMaskInput(vtkImageData* mask)
{
  if (this->Internal->Mask != mask)
  {
    this->Internal->Mask = mask;
    this->Modified();
  }
}

void vtkMultiMaterialVolumeMapper::SetMultiMaterialProperty(vtkMultiMaterialProperty* property)
{
  if (this->Internal->MultiMaterial != property)
  {
    this->Internal->MultiMaterial = property; // another source of materials: the proxies are made again
    this->Modified();
  }
}

vtkMultiMaterialProperty* vtkMultiMaterialVolumeMapper::GetMultiMaterialProperty()
{
  return this->Internal->MultiMaterial;
}

void vtkMultiMaterialVolumeMapper::SetEnvironmentTexture(vtkTexture* texture)
{
  if (this->Internal->EnvironmentTexture != texture)
  {
    this->Internal->EnvironmentTexture = texture;
    this->Modified();
  }
}

vtkTexture* vtkMultiMaterialVolumeMapper::GetEnvironmentTexture()
{
  return this->Internal->EnvironmentTexture;
}

vtkImageData* vtkMultiMaterialVolumeMapper::GetMaskInput()
{
  return this->Internal->Mask;
}

int vtkMultiMaterialVolumeMapper::GetAccumulatedSamples()
{
  const mmrtm::Film* film = this->Internal->ImageFilm();
  return film ? static_cast<int>(film->Samples()) : 0;
}

void vtkMultiMaterialVolumeMapper::SetLabelMaterial(int label, double r, double g, double b, double opacity)
{
  mmrtm::LabelLook look;
  look.color = { r, g, b };
  look.opacity = opacity;
  auto& looks = this->Internal->LabelLooks;
  const auto found = looks.find(label);
  if (found != looks.end() && found->second.color == look.color && found->second.opacity == opacity)
    return;
  looks[label] = look;
  this->Modified();
}

bool vtkMultiMaterialVolumeMapper::GetLabelMaterial(int label, double rgbo[4])
{
  const auto found = this->Internal->LabelLooks.find(label);
  if (found == this->Internal->LabelLooks.end())
    return false;
  for (int c = 0; c < 3; ++c)
    rgbo[c] = found->second.color[c];
  rgbo[3] = found->second.opacity;
  return true;
}

void vtkMultiMaterialVolumeMapper::RemoveLabelMaterial(int label)
{
  if (this->Internal->LabelLooks.erase(label))
    this->Modified();
}

void vtkMultiMaterialVolumeMapper::RemoveAllLabelMaterials()
{
  if (this->Internal->LabelLooks.empty())
    return;
  this->Internal->LabelLooks.clear();
  this->Modified();
}

void vtkMultiMaterialVolumeMapper::SetLabelMaterialParameters(int label, const char* json)
{
  auto& parameters = this->Internal->LabelMaterialParameters;
  const auto found = parameters.find(label);
  if (!json || !*json)
  {
    if (found == parameters.end())
      return;
    parameters.erase(found);
  }
  else
  {
    if (found != parameters.end() && found->second == json)
      return;
    parameters[label] = json;
  }
  this->Modified();
}

const char* vtkMultiMaterialVolumeMapper::GetLabelMaterialParameters(int label)
{
  const auto found = this->Internal->LabelMaterialParameters.find(label);
  return found == this->Internal->LabelMaterialParameters.end() ? nullptr : found->second.c_str();
}

void vtkMultiMaterialVolumeMapper::RemoveAllLabelMaterialParameters()
{
  if (this->Internal->LabelMaterialParameters.empty())
    return;
  this->Internal->LabelMaterialParameters.clear();
  this->Modified();
}

double vtkMultiMaterialVolumeMapper::GetRelativeNoise()
{
  const mmrtm::Film* film = this->Internal->ImageFilm();
  return film && film->Samples() >= 2 ? film->Noise().relative : 0.0;
}

bool vtkMultiMaterialVolumeMapper::IsConverged()
{
  const mmrtm::Film* film = this->Internal->ImageFilm();
  if (!this->Internal->FilmConverged())
    return false;
  // The image shown is final once no denoise is running or due.
  Internals& in = *this->Internal;
  return !(in.InFlight && in.InFlight->Denoising) &&
    !(this->Internal->DenoisingApplies() && in.Display.Due(in.FilmGeneration, film->Samples(), false));
}

void vtkMultiMaterialVolumeMapper::GetAccumulatedImage(vtkImageData* image)
{
  if (!image)
    return;
  image->Initialize();
  const mmrtm::Film* film = this->Internal->ImageFilm();
  if (!film || film->Samples() == 0)
    return;
  const int width = film->Width(), height = film->Height();
  image->SetDimensions(width, height, 1);
  vtkNew<vtkFloatArray> values;
  values->SetName("AccumulatedImage");
  values->SetNumberOfComponents(4);
  values->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
  for (int y = 0; y < height; ++y)
  {
    const int row = height - 1 - y; // the film's row 0 is the top, VTK's the bottom
    for (int x = 0; x < width; ++x)
    {
      const mmrtm::RGB c = film->Mean(x, y);
      const float rgba[4] = { c.r, c.g, c.b, film->Alpha(x, y) };
      values->SetTypedTuple(static_cast<vtkIdType>(row) * width + x, rgba);
    }
  }
  image->GetPointData()->SetScalars(values);
}

const char* vtkMultiMaterialVolumeMapper::GetDisplayStatus()
{
  Internals& in = *this->Internal;
  const mmrtm::Film* film = this->Internal->ImageFilm();
  switch (in.LastShown)
  {
    case Internals::ShownImage::Nothing:
      in.DisplayStatus = "nothing shown yet";
      break;
    case Internals::ShownImage::Preview:
      in.DisplayStatus = in.ShowedDenoised ? "preview, denoised" : "preview";
      break;
    case Internals::ShownImage::Other:
      in.DisplayStatus = "unbiased, " + std::to_string(in.LastShownSamples) + " samples (combined)";
      break;
    case Internals::ShownImage::Film:
      in.DisplayStatus = in.Display.Status(in.FilmGeneration, in.LastShownSamples,
        film && film->Samples() == in.LastShownSamples && film->Samples() >= 2 ? film->Noise().relative : 0.0);
      break;
  }
  return in.DisplayStatus.c_str();
}

bool vtkMultiMaterialVolumeMapper::IsDenoisedImageShown()
{
  return this->Internal->ShowedDenoised;
}

void vtkMultiMaterialVolumeMapper::GetDisplayedImage(vtkImageData* image)
{
  // What a frame drawn now would show of the film (previews are not kept).
  Internals& in = *this->Internal;
  const mmrtm::Film* film = this->Internal->ImageFilm();
  if (film)
    in.Display.Recheck(*film, in.FilmGeneration);
  const mmrtm::DenoisedFilm* denoised =
    film && this->Internal->DenoisingApplies() ? in.Display.Shown(in.FilmGeneration, film->Samples()) : nullptr;
  if (!denoised)
  {
    this->GetAccumulatedImage(image);
    return;
  }
  if (!image)
    return;
  image->Initialize();
  const int width = denoised->image.width, height = denoised->image.height;
  image->SetDimensions(width, height, 1);
  vtkNew<vtkFloatArray> values;
  values->SetName("DisplayedImage");
  values->SetNumberOfComponents(4);
  values->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
    {
      const size_t i = static_cast<size_t>(y) * width + x;
      const mmrtm::RGB c = denoised->image.pixels[i];
      const float rgba[4] = { c.r, c.g, c.b, denoised->alpha[i] };
      values->SetTypedTuple(static_cast<vtkIdType>(height - 1 - y) * width + x, rgba);
    }
  image->GetPointData()->SetScalars(values);
}

int vtkMultiMaterialVolumeMapper::GetNumberOfDenoises()
{
  return this->Internal->Display.Denoises() + this->Internal->PreviewDenoises;
}

double vtkMultiMaterialVolumeMapper::GetDenoisingSeconds()
{
  return this->Internal->Display.Seconds() + this->Internal->PreviewDenoiseSeconds;
}

double vtkMultiMaterialVolumeMapper::GetLastDenoiseSeconds()
{
  return this->Internal->Display.LastSeconds();
}

double vtkMultiMaterialVolumeMapper::GetEstimatedDenoisedError()
{
  const mmrtm::DenoiseEstimate* e = this->Internal->Display.Estimate(this->Internal->FilmGeneration);
  return e && e->meanValue > 0 ? std::sqrt(e->denoised) / e->meanValue : -1.0;
}

double vtkMultiMaterialVolumeMapper::GetEstimatedFilmError()
{
  const mmrtm::DenoiseEstimate* e = this->Internal->Display.Estimate(this->Internal->FilmGeneration);
  return e && e->meanValue > 0 ? std::sqrt(e->film) / e->meanValue : -1.0;
}

int vtkMultiMaterialVolumeMapper::GetNumberOfSceneBuilds()
{
  return this->Internal->SceneBuilds;
}

double vtkMultiMaterialVolumeMapper::GetLastRefitSeconds()
{
  return this->Internal->LastBuildSeconds;
}

int vtkMultiMaterialVolumeMapper::GetNumberOfMajorantGridBuilds()
{
  return this->Internal->GridBuilds;
}

int vtkMultiMaterialVolumeMapper::GetNumberOfMajorantGridRefits()
{
  return this->Internal->GridRefits;
}

int vtkMultiMaterialVolumeMapper::GetNumberOfRefits()
{
  return this->Internal->Refits;
}

int vtkMultiMaterialVolumeMapper::GetNumberOfInteractiveRenders()
{
  return this->Internal->InteractiveRenders;
}

int vtkMultiMaterialVolumeMapper::GetNumberOfTracedPasses()
{
  return this->Internal->TracedPasses;
}

void vtkMultiMaterialVolumeMapper::GetLastFilmSize(int size[2])
{
  size[0] = this->Internal->LastFilmSize[0];
  size[1] = this->Internal->LastFilmSize[1];
}

int vtkMultiMaterialVolumeMapper::GetNumberOfRestarts()
{
  return this->Internal->Restarts;
}

void vtkMultiMaterialVolumeMapper::GetDefaultLabelColor(int label, double rgb[3])
{
  const mmrtm::RGB c = mmrtm::DefaultLabelColor(label);
  rgb[0] = c.r;
  rgb[1] = c.g;
  rgb[2] = c.b;
}

bool vtkMultiMaterialVolumeMapper::GetLabelsPresent(vtkImageData* labelMap, vtkIdList* labels)
{
  labels->Reset();
  try
  {
    if (!labelMap)
      throw mmrtm::InputError("no label map");
    vtkDataArray* scalars = labelMap->GetPointData()->GetScalars();
    if (scalars && scalars->GetNumberOfComponents() != 1)
      throw mmrtm::InputError("the label map has " + std::to_string(scalars->GetNumberOfComponents()) +
        " components, not 1");
    const mmrtm::HostVolume volume =
      mmrtm::ImageDataToHostVolume(labelMap, scalars, 0, "the label map", mmrtm::Interpolation::Nearest);
    for (const int label : mmrtm::LabelIdsPresent(volume))
      labels->InsertNextId(label);
    return true;
  }
  catch (const std::exception& e)
  {
    labels->Reset();
    vtkGenericWarningMacro("GetLabelsPresent: " << e.what());
    return false;
  }
}

double vtkMultiMaterialVolumeMapper::GetLabelDensityAtFullOpacity()
{
  return mmrtm::kLabelDensityAtFullOpacity;
}

const char* vtkMultiMaterialVolumeMapper::GetBackendDescription()
{
  return this->Internal->BackendDescription.c_str();
}

// The phases of a render, as vtkGPUVolumeRayCastMapper has them: validate,
// read the inputs and compare them with what the scene was made from, stop
// a pass in flight that they outdate, update the proxies, the materials and
// the view as far as they changed, refine, draw.
namespace
{
// Whether VTK's dual depth peeling is rendering the volumes (the renderer's
// UseDepthPeelingForVolumes with translucent geometry): its passes are in
// the volume's render-pass key then.
bool InDualDepthPeeling(vtkVolume* vol)
{
  vtkInformation* info = vol->GetPropertyKeys();
  if (!info || !info->Has(vtkOpenGLRenderPass::RenderPasses()))
    return false;
  vtkInformationObjectBaseVectorKey* key = vtkOpenGLRenderPass::RenderPasses();
  for (int i = 0; i < key->Length(info); ++i)
    if (vtkObjectBase* pass = key->Get(info, i))
      if (pass->IsA("vtkDualDepthPeelingPass"))
        return true;
  return false;
}
}

void vtkMultiMaterialVolumeMapper::Render(vtkRenderer* ren, vtkVolume* vol)
{
  const auto start = std::chrono::steady_clock::now();
  this->InvokeEvent(vtkCommand::VolumeMapperRenderStartEvent, nullptr);
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!InDualDepthPeeling(vol) || !window || !window->GetRenderFramebuffer())
    this->Internal->RenderFrame(ren, vol);
  else if (this->Internal->TracesInThisFrame(ren))
  {
    // The peels' shaders split a ray into depth ranges between translucent
    // layers; the film has no such layers. It is traced once and drawn into
    // the window's framebuffer (its depth is the opaque geometry's, which
    // stops the camera rays), over which the peeling blends all translucent
    // layers when it finishes. Later calls of the frame draw nothing: the
    // film is already there.
    vtkOpenGLState* state = window->GetState();
    state->PushFramebufferBindings();
    window->GetRenderFramebuffer()->Bind();
    GLint equation = GL_FUNC_ADD;
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &equation); // the peels blend by GL_MAX
    state->vtkglBlendEquation(GL_FUNC_ADD);
    {
      vtkOpenGLState::ScopedglEnableDisable cull(state, GL_CULL_FACE);
      state->vtkglDisable(GL_CULL_FACE);
      this->Internal->RenderFrame(ren, vol);
    }
    state->vtkglBlendEquation(static_cast<unsigned int>(equation));
    state->PopFramebufferBindings();
  }
  this->TimeToDraw = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  this->InvokeEvent(vtkCommand::VolumeMapperRenderEndEvent, nullptr);
}

bool vtkMultiMaterialVolumeMapper::Internals::TracesInThisFrame(vtkRenderer* ren)
{
  Internals& in = *this;
  Internals::PeelFrame* frame = nullptr;
  for (const auto& f : in.PeelFrames)
    if (f->Renderer == ren)
      frame = f.get();
  if (!frame)
  {
    in.PeelFrames.push_back(std::make_unique<Internals::PeelFrame>());
    frame = in.PeelFrames.back().get();
    frame->Renderer = ren;
    vtkNew<vtkCallbackCommand> newFrame;
    newFrame->SetClientData(frame);
    newFrame->SetCallback(
      [](vtkObject*, unsigned long, void* data, void*) { static_cast<Internals::PeelFrame*>(data)->Traced = false; });
    frame->Observer = ren->AddObserver(vtkCommand::StartEvent, newFrame);
  }
  const bool first = !frame->Traced;
  frame->Traced = true;
  return first;
}

// The phases of one frame's image, drawn into the bound framebuffer.
void vtkMultiMaterialVolumeMapper::Internals::RenderFrame(vtkRenderer* ren, vtkVolume* vol)
{
  Internals& in = *this;
  const auto start = std::chrono::steady_clock::now();
  auto draw = [&](const mmrtm::Film& film)
  {
    in.LastFilmSize[0] = film.Width();
    in.LastFilmSize[1] = film.Height();
    Self->DrawFilm(ren, vol, film);
  };
  int viewport[4] = { 0, 0, 0, 0 }; // width, height, origin x, origin y
  if (!this->ValidateInputs(ren, vol, viewport))
    return;
  try
  {
    // A pass in flight reads the input's voxels in place: it stops before
    // the pipeline runs again, which may rewrite or reallocate them.
    if (in.InFlight && this->InputWillExecute())
      this->FinishPass(true);
    InputState now = this->ReadInputs(ren, vol, viewport);
    const Changes changes = this->ChangesSince(in.Built, now);

    // Asynchronous refinement: a pass in flight goes on while nothing
    // changed (the last finished image is drawn); else it is stopped.
    vtkRenderWindow* window = ren->GetRenderWindow();
    const bool interactive = Self->InteractiveAdjustResolution && window->GetDesiredUpdateRate() > 1.0;
    if (in.InFlight)
    {
      if (!in.InFlight->Done && !interactive && !changes.Any())
      {
        if (in.Shown)
          draw(*in.Shown);
        return;
      }
      this->FinishPass(!in.InFlight->Done); // a stopped pass leaves no film: a restart
    }

    if (changes.Proxies)
      this->UpdateProxies(now);
    else if (changes.Description)
      this->UpdateDescription(now);
    if (!now.Proxies.MultiMaterial && (changes.Proxies || changes.Materials))
      this->UpdateMaterials(now);
    // A preview leaves no film (the still render after the interaction
    // starts again at full resolution); previews between changes are drawn
    // from the scene as it is: no restart.
    const bool restart = changes.Any() || (!in.Film && !interactive);
    if (changes.Proxies || changes.Description || changes.Materials)
      in.ParkedFilm.reset(); // accumulated under the scene before
    if (restart)
      this->UpdateView(ren, vol, now);
    // A still render that restarts with nothing changed since the preview
    // before it (the end of a drag, a front end's preview of a change):
    // that preview, denoised, stands for the new accumulation until the
    // first denoise of it (its first pass alone is the noisier image).
    if (restart && !interactive)
      in.PreviewStandsFor = !changes.Any() && in.PreviewDenoised ? in.FilmGeneration : 0;
    this->UpdateRenderer();

    if (interactive)
    {
      // The volume's share of the frame (VTK's renderer divides the
      // window's 1 / DesiredUpdateRate among its props).
      const double allocated = vol->GetAllocatedRenderTime();
      const double budget = allocated > 0 && allocated < 1e6 ? allocated : 1.0 / window->GetDesiredUpdateRate();
      const double traced = this->RenderPreview(ren, viewport[0], viewport[1]);
      draw(*in.Preview);
      this->AdaptPreview(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), traced, budget);
      return;
    }
    in.Preview.reset();
    if (const mmrtm::Film* film = this->Refine(restart))
      draw(*film);
  }
  catch (const std::exception& e)
  {
    vtkErrorWithObjectMacro(Self, "Render: " << e.what());
  }
}

void vtkMultiMaterialVolumeMapper::DrawFilm(vtkRenderer* ren, vtkVolume* vol, const mmrtm::Film& film)
{
  // A projection's film holds VTK's colours made linear: no curve.
  const mmrtm::RenderSettings& rs = this->Internal->Scene.render;
  const bool description = this->Internal->MultiMaterial != nullptr;
  const mmrtm::ToneMapper toneMapper = rs.integrator.projection.mode != mmrtm::IntensityProjection::None
    ? mmrtm::ToneMapper::Clamp
    : this->ToneMapping == FILMIC_TONE_MAPPING                   ? mmrtm::ToneMapper::Filmic
    : this->ToneMapping == AUTOMATIC_TONE_MAPPING && description ? rs.toneMapper // the description's
                                                                 : mmrtm::ToneMapper::Off;
  // What the display shows of the film (DenoisingMode): the mapper's own
  // film or preview (a film combined from other processes has no denoiser
  // inputs: it is shown as it is).
  Internals& in = *this->Internal;
  const mmrtm::RGBImage* denoised = nullptr;
  const std::vector<float>* denoisedAlpha = nullptr;
  in.LastShown = Internals::ShownImage::Other;
  if (&film == in.Preview.get())
  {
    if (in.PreviewDenoised)
    {
      denoised = &in.PreviewDenoised->image;
      denoisedAlpha = &in.PreviewDenoised->alpha;
    }
    in.LastShown = Internals::ShownImage::Preview;
  }
  else if (&film == this->Internal->ImageFilm())
  {
    in.LastShown = Internals::ShownImage::Film;
    in.Display.Recheck(film, in.FilmGeneration);
    const mmrtm::DenoisedFilm* shown =
      this->Internal->DenoisingApplies() ? in.Display.Shown(in.FilmGeneration, film.Samples()) : nullptr;
    if (shown)
    {
      denoised = &shown->image;
      denoisedAlpha = &shown->alpha;
    }
    else if (this->Internal->DenoisingApplies() && in.PreviewDenoised && in.PreviewStandsFor == in.FilmGeneration &&
      !in.Display.HasDenoised(in.FilmGeneration))
    {
      denoised = &in.PreviewDenoised->image;
      denoisedAlpha = &in.PreviewDenoised->alpha;
      in.LastShown = Internals::ShownImage::Preview;
    }
  }
  in.LastShownSamples = film.Samples();
  in.ShowedDenoised = denoised != nullptr;
  // The image: tone-mapped, premultiplied RGBA, bottom row first for OpenGL.
  const int width = denoised ? denoised->width : film.Width(), height = denoised ? denoised->height : film.Height();
  std::vector<uint8_t> rgba;
  if (denoised)
  {
    rgba.resize(4 * denoised->pixels.size());
    for (size_t i = 0; i < denoised->pixels.size(); ++i)
    {
      uint8_t* p = &rgba[4 * i];
      mmrtm::ToneMapPixel(denoised->pixels[i], static_cast<float>(this->Exposure), toneMapper, p);
      p[3] = static_cast<uint8_t>(mmrtm::Clamp((*denoisedAlpha)[i], 0.f, 1.f) * 255.f + 0.5f);
    }
  }
  else
    rgba = film.ToneMapped(static_cast<float>(this->Exposure), toneMapper, 4);
  const size_t row = 4 * static_cast<size_t>(width);
  for (int y = 0; y < height / 2; ++y)
    std::swap_ranges(rgba.begin() + y * row, rgba.begin() + (y + 1) * row, rgba.begin() + (height - 1 - y) * row);

  // Drawn over the whole viewport (a preview is stretched), in front of
  // everything: the camera rays already stopped at the opaque geometry, so
  // where it is in front the image is transparent.
  const float depth = 1e-6f;
  vtkSmartPointer<vtkRayCastImageDisplayHelper>& helper = this->Internal->DisplayHelper;
  if (!helper)
  {
    helper = vtkSmartPointer<vtkRayCastImageDisplayHelper>::Take(vtkRayCastImageDisplayHelper::New());
    if (!helper)
    {
      vtkErrorMacro("no OpenGL image display helper: load VTK::RenderingVolumeOpenGL2");
      return;
    }
    helper->PreMultipliedColorsOn();
  }
  int viewport[4];
  ren->GetTiledSizeAndOrigin(&viewport[0], &viewport[1], &viewport[2], &viewport[3]);
  int origin[2] = { 0, 0 };
  if (width != viewport[0] || height != viewport[1])
  {
    int size[2] = { width, height }; // a preview: stretched
    helper->RenderTexture(vol, ren, size, size, size, origin, depth, rgba.data());
    return;
  }
  // The helper maps the quad's corners to texel centres, which resamples
  // the image by (n - 1) / n: up to half a pixel of blur towards the
  // edges, the more the smaller the image (a tile of a magnified
  // screenshot blurred its middle). Each pixel drawn as 2 x 2 texels, the
  // viewport counted twice as large, puts every pixel's sample among its
  // own texels: the image is drawn as it is.
  std::vector<uint8_t> doubled(4 * rgba.size());
  for (int y = 0; y < 2 * height; ++y)
    for (int x = 0; x < 2 * width; ++x)
      std::copy_n(&rgba[4 * (static_cast<size_t>(y / 2) * width + x / 2)], 4,
        &doubled[4 * (static_cast<size_t>(y) * 2 * width + x)]);
  int size[2] = { 2 * width, 2 * height };
  helper->RenderTexture(vol, ren, size, size, size, origin, depth, doubled.data());
}

void vtkMultiMaterialVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  // The display helper's texture and shader (the tracer holds no graphics).
  if (this->Internal->DisplayHelper)
    this->Internal->DisplayHelper->ReleaseGraphicsResources(window);
}

void vtkMultiMaterialVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SamplesPerRender: " << this->SamplesPerRender << "\n";
  os << indent << "MaximumSamples: " << this->MaximumSamples << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Backend: " << this->Backend << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "ShadowExtinctionScale: " << this->ShadowExtinctionScale << "\n";
  os << indent << "NoiseTarget: " << this->NoiseTarget << "\n";
  os << indent << "Accelerator: " << this->Accelerator << "\n";
  os << indent << "Sampler: " << (this->Sampler == INDEPENDENT ? "independent" : "sobol") << "\n";
  os << indent << "MaximumBounces: " << this->MaximumBounces << "\n";
  os << indent << "ImageSampleDistance: " << this->ImageSampleDistance << "\n";
  os << indent << "MinimumImageSampleDistance: " << this->MinimumImageSampleDistance << "\n";
  os << indent << "MaximumImageSampleDistance: " << this->MaximumImageSampleDistance << "\n";
  os << indent << "AutoAdjustSampleDistances: " << this->AutoAdjustSampleDistances << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "AccumulatedSamples: " << this->GetAccumulatedSamples() << "\n";
}
