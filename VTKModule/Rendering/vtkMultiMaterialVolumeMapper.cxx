#include "vtkMultiMaterialVolumeMapper.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDemandDrivenPipeline.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkColorTransferFunction.h>
#include <vtkContourValues.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkInformationObjectBaseVectorKey.h>
#include <vtkLight.h>
#include <vtkLightCollection.h>
#include <vtkMatrix4x4.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLRenderPass.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkRayCastImageDisplayHelper.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkPointData.h>
#include <vtkRectilinearGrid.h>
#include <vtkTexture.h>
#include <vtkTimeStamp.h>
#include <vtkSmartPointer.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWeakPointer.h>
#if __has_include(<vtk_glad.h>)
#include <vtk_glad.h> // VTK 9.4 and later: the GL enums
#else
#include <vtk_glew.h>
#endif

#include "denoised_display.h"
#include "denoiser.h"
#include "derived_proxies.h"
#include "film.h"
#include "label_alignment.h"
#include "label_materials.h"
#include "mmrtmImageDataConversion.h"
#include "mmrtmTracedImage.h"
#include "mmrtmVolumePropertyFunctions.h"
#include "mmrtmVtkSceneTranslation.h"
#include "mmrtm/planted_defect.h"
#include "render_backend.h"
#include "scene.h"
#include "scene_json.h"
#include "vtkMultiMaterialProperty.h"

vtkStandardNewMacro(vtkMultiMaterialVolumeMapper);

// What a render reads, in three parts, each of which decides one phase's
// work: the proxies (voxels, mask, the components the property uses), the
// materials (the property, the multi-material description, the label
// parameters) and the view (camera, lights, viewport, clipping, opaque
// geometry, environment, the mapper's tracing settings). Modification
// times where VTK keeps them; the view by value (SameView).
struct vtkMultiMaterialVolumeMapper::InputState
{
  struct ProxyInputs
  {
    vtkImageData* Data = nullptr;
    vtkMTimeType DataTime = 0;
    vtkDataArray* Scalars = nullptr; // the array the mapper's scalar mode picks
    vtkImageData* Mask = nullptr;
    vtkMTimeType MaskTime = 0;
    int MaskType = -1;
    vtkMultiMaterialProperty* MultiMaterial = nullptr;
    int Dependent = -1;          // components used as colour + opacity (IndependentComponents off)
    int Independent = -1;        // components mixed additively (IndependentComponents on)
    int ComponentGradients = -1; // independent components with gradient opacity (bit c)
    bool NeedGradient = false;   // a gradient-magnitude proxy (without a description)
    bool operator==(const ProxyInputs& o) const
    {
      return std::tie(this->Data, this->DataTime, this->Scalars, this->Mask, this->MaskTime, this->MaskType,
               this->MultiMaterial, this->Dependent, this->Independent, this->ComponentGradients, this->NeedGradient) ==
        std::tie(o.Data, o.DataTime, o.Scalars, o.Mask, o.MaskTime, o.MaskType, o.MultiMaterial, o.Dependent,
          o.Independent, o.ComponentGradients, o.NeedGradient);
    }
  } Proxies;

  struct MaterialInputs
  {
    vtkVolumeProperty* Property = nullptr;
    vtkMTimeType PropertyTime = 0, MultiMaterialTime = 0, LabelMaterialsTime = 0;
    mmrtm::TranslationOptions Options; // the mapper's: unshaded scattering, isosurfaces
  } Materials;

  struct ViewInputs
  {
    int Width = 0, Height = 0;         // the viewport's
    int FilmWidth = 0, FilmHeight = 0; // the still film's: the viewport's over the image sample distance
    std::vector<double> Values;        // camera, lights, matrix, size, clipping, environment: SameView
    std::vector<mmrtm::ClipPlane> Clip;
    std::vector<float> Depth; // the depth buffer under the volume
    vtkMTimeType TracingTime = 0;
    // Which view of the mapper's this is: a renderer and volume (one
    // mapper may serve several), and whether it is a tile of a magnified
    // image (vtkWindowToImageFilter::SetScale, vtkRenderLargeImage).
    vtkRenderer* Renderer = nullptr;
    vtkVolume* Volume = nullptr;
    bool Tile = false;
  } View;
};

// Which phases a render must run: the answer of ChangesSince.
struct vtkMultiMaterialVolumeMapper::Changes
{
  bool Proxies = false;     // made again from the input (and the description parsed over them)
  bool Description = false; // the description parsed again over the proxies as they are
  bool Materials = false;   // the property translated again
  bool View = false;        // the camera, lights and settings set again
  bool Any() const { return this->Proxies || this->Description || this->Materials || this->View; }
};

// What the mapper keeps between renders, and the inputs it was made from.
struct vtkMultiMaterialVolumeMapper::Internals
{
  mmrtm::Scene Scene;
  std::unique_ptr<mmrtm::Renderer> Renderer;
  int RendererBackend = -1, RendererThreads = -1;
  std::unique_ptr<mmrtm::Film> Film;
  std::string BackendDescription;
  vtkNew<vtkMatrix4x4> Matrix; // the volume's matrix at the last render
  // Draws the image as a texture: the OpenGL helper, from the object factory
  // at the first draw (RenderingVolumeOpenGL2 must be loaded by then).
  vtkSmartPointer<vtkRayCastImageDisplayHelper> DisplayHelper;

  // Index-to-world of each proxy before the volume's matrix.
  std::vector<mmrtm::Affine3> ImageIndexToWorld;
  mmrtm::ProxyLayout Layout;
  vtkSmartPointer<vtkImageData> Mask;
  vtkSmartPointer<vtkMultiMaterialProperty> MultiMaterial;
  bool LightsFromScene = false; // the multi-material description has its own lights
  vtkSmartPointer<vtkTexture> EnvironmentTexture;
  std::shared_ptr<mmrtm::EnvironmentMap> Environment; // converted from the texture
  vtkMTimeType EnvironmentTime = 0;
  double EnvironmentScale = 0;
  // SetLabelMaterial and SetLabelMaterialParameters, by label.
  std::map<int, mmrtm::LabelLook> LabelLooks;
  std::map<int, std::string> LabelMaterialParameters;
  // When they last changed as values: labels removed and set again to the
  // looks they had (a front end that sets all its labels at each update)
  // are no change.
  vtkMTimeType LabelMaterialsTime()
  {
    if (this->LabelLooks != this->LabelLooksSeen || this->LabelMaterialParameters != this->LabelParametersSeen)
    {
      this->LabelLooksSeen = this->LabelLooks;
      this->LabelParametersSeen = this->LabelMaterialParameters;
      this->LabelMaterialsChanged.Modified();
    }
    return this->LabelMaterialsChanged.GetMTime();
  }
  std::map<int, mmrtm::LabelLook> LabelLooksSeen;
  std::map<int, std::string> LabelParametersSeen;
  vtkTimeStamp LabelMaterialsChanged;
  // The looks with their parameters (a description's label classes).
  std::map<int, mmrtm::LabelLook> LabelLooksWithParameters() const
  {
    std::map<int, mmrtm::LabelLook> looks = this->LabelLooks;
    for (auto& [label, look] : looks)
      if (const auto found = this->LabelMaterialParameters.find(label); found != this->LabelMaterialParameters.end())
      {
        look.surface = mmrtm::ParseJson(found->second, "label " + std::to_string(label) + " material");
        if (!look.surface.is_object())
          throw mmrtm::InputError("label " + std::to_string(label) + " material: expected a JSON object");
      }
    return looks;
  }
  // The inputs as the scene and the film were last made from them; each
  // render compares what it finds with these (ChangesSince).
  InputState Built;
  // The accumulation of the view before, while another is drawn: the whole
  // view during the tiles of a magnified screenshot, or another renderer's
  // or volume's view of this mapper. The film goes on when its view comes
  // back (TakeFilm); a change of the scene drops it.
  std::unique_ptr<mmrtm::Film> ParkedFilm;
  InputState::ViewInputs ParkedView;
  bool HasScene = false; // false until a build succeeds, and after a failed one

  // Whether each warning's cause held when it was last checked: a warning
  // is said when its cause appears, and again only after the cause went
  // away and came back (each its own flag: one shared flag silenced the
  // others after the first).
  std::map<std::string, bool> WarningCauses;
  bool Warn(const std::string& warning, bool cause)
  {
    bool& held = this->WarningCauses[warning];
    const bool say = cause && !held;
    held = cause;
    return say;
  }

  // The last input converted for the tracer (ReadTracedImage), with what
  // it was converted from.
  struct Conversion
  {
    vtkDataSet* Input = nullptr;
    vtkMTimeType InputTime = 0;
    vtkDataArray* Scalars = nullptr;
    vtkMTimeType ScalarsTime = 0;
    bool Cell = false;
    mmrtm::TracedImage Traced;
  } Converted;

  // Asynchronous refinement: the pass in flight adds samples to Film on a
  // thread of its own while renders draw Shown (Film as of the last pass
  // that finished). A pass starts only when nothing changed, so it runs
  // under Built: a render that finds any change stops it (between tiles)
  // first.
  struct Pass
  {
    std::thread Thread;
    std::atomic<bool> Cancel{ false }, Done{ false }, Completed{ false };
    std::string Error;
    bool Denoising = false; // a denoise of Shown, not samples
    std::optional<mmrtm::DenoisedFilm> Denoised;
  };
  std::unique_ptr<Pass> InFlight;
  std::unique_ptr<mmrtm::Film> Shown;

  // The denoised display (DenoisingMode): what the frames show of the
  // film. FilmGeneration numbers the film's accumulations (a restart or a
  // reset starts a new one), so that a denoise of one is never shown over
  // another.
  mmrtm::DenoisedDisplay Display;
  uint64_t FilmGeneration = 0;
  std::unique_ptr<mmrtm::Denoiser> Denoiser; // loaded at the first need
  bool DenoiserLoadTried = false;
  std::optional<mmrtm::DenoisedFilm> PreviewDenoised; // the interactive preview, when denoised
  uint64_t PreviewStandsFor = 0;                      // the accumulation it stands for (RenderFrame), or 0
  double PreviewDenoiseSeconds = 0;
  int PreviewDenoises = 0;
  // What the last frame drew: the mapper's film (or the copy of it that
  // asynchronous refinement draws), a preview, or another film (combined
  // from other processes); how many samples it had; whether denoised.
  enum class ShownImage
  {
    Nothing,
    Film,
    Preview,
    Other
  } LastShown = ShownImage::Nothing;
  uint32_t LastShownSamples = 0;
  bool ShowedDenoised = false;
  std::string DisplayStatus; // GetDisplayStatus's

  // What GetTracingMTime last found (TracingInputs), and when it changed.
  std::vector<double> TracingInputsSeen;
  vtkTimeStamp TracingInputsTime;

  int SceneBuilds = 0, Refits = 0, Restarts = 0, InteractiveRenders = 0, GridBuilds = 0, GridRefits = 0;
  // After a Scene.Build: what it did to the majorant grid.
  void CountGridWork()
  {
    this->GridBuilds += this->Scene.GridSummariesBuiltByLastBuild() ? 1 : 0;
    this->GridRefits += this->Scene.GridRefittedByLastBuild() ? 1 : 0;
  }
  std::string LastExtinctionWarning; // said once per change (vtkWarningMacro)
  double LastBuildSeconds = 0;
  // While the interactor moves the camera: a preview with an image sample
  // distance of PreviewDistance (1/PreviewDistance of the resolution), 1
  // sample per pixel, the distance adapted to the volume's allocated time.
  std::unique_ptr<mmrtm::Film> Preview;
  double PreviewDistance = 4.0;
  int TracedPasses = 0;
  int LastFilmSize[2] = { 0, 0 };

  // Depth peeling for volumes calls Render once per peel: each renderer's
  // StartEvent marks a new frame (Traced false), and the first call of a
  // frame traces and draws it.
  struct PeelFrame
  {
    vtkWeakPointer<vtkRenderer> Renderer;
    unsigned long Observer = 0;
    bool Traced = false;
  };
  std::vector<std::unique_ptr<PeelFrame>> PeelFrames;
};

namespace
{
// Global illumination off: the shadow rays' extinction scale. The tracer
// takes a scale above 0; at this one a shadow ray through the densest
// tissue the translation makes (an optical depth of 64 per voxel) over
// 1000 voxels transmits 0.94, everything lighter nearly 1.
constexpr float kLocalLightingShadowScale = 1e-6f;

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

// Camera, lights, the volume's matrix and the viewport, as values: a change
// restarts the accumulation. Values rather than modification times, because
// VTK swaps in near copies (vtkWindowToImageFilter renders with a copy of
// the camera whose view angle is off by 1e-8): a screenshot must not restart.
std::vector<double> ViewSignature(vtkRenderer* ren, vtkVolume* vol, int width, int height)
{
  std::vector<double> v{ static_cast<double>(width), static_cast<double>(height) };
  auto add = [&v](const double* p, int n) { v.insert(v.end(), p, p + n); };
  vtkCamera* cam = ren->GetActiveCamera();
  add(cam->GetPosition(), 3);
  add(cam->GetFocalPoint(), 3);
  add(cam->GetViewUp(), 3);
  add(cam->GetWindowCenter(), 2);
  v.push_back(cam->GetViewAngle());
  v.push_back(cam->GetParallelProjection());
  v.push_back(cam->GetParallelScale());
  vtkNew<vtkMatrix4x4> m;
  vol->GetMatrix(m);
  add(&m->Element[0][0], 16);
  vtkLightCollection* lights = ren->GetLights();
  lights->InitTraversal();
  while (vtkLight* l = lights->GetNextItem())
  {
    double p[3], f[3];
    l->GetTransformedPosition(p);
    l->GetTransformedFocalPoint(f);
    add(p, 3);
    add(f, 3);
    add(l->GetDiffuseColor(), 3);
    v.push_back(l->GetIntensity());
    v.push_back(l->GetSwitch());
    v.push_back(l->GetPositional());
  }
  return v;
}

// Equal to a relative 1e-6: vtkWindowToImageFilter renders with a camera
// whose view angle went through tan and atan.
bool SameView(const std::vector<double>& a, const std::vector<double>& b)
{
  if (a.size() != b.size())
    return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i] - b[i]) > 1e-6 * std::max({ 1.0, std::abs(a[i]), std::abs(b[i]) }))
      return false;
  return true;
}

// The depth buffer of the viewport (opaque geometry drawn before volumes),
// window depth in [0, 1], rows bottom first; empty without any geometry.
std::vector<float> ReadDepth(vtkRenderer* ren, int width, int height, int x0, int y0)
{
  std::vector<float> depth(static_cast<size_t>(width) * height, 1.f);
  ren->GetRenderWindow()->GetZbufferData(x0, y0, x0 + width - 1, y0 + height - 1, depth.data());
  for (float z : depth)
    if (z < 1.f)
      return depth;
  return {};
}

// Pixels of a film over `size` viewport pixels at an image sample distance.
int FilmSize(int size, double distance)
{
  return std::max(1, static_cast<int>(std::ceil(size / distance - 1e-9)));
}

// The viewport's depth buffer (width x height) at the pixel centres of a
// film of w x h stretched over it.
std::vector<float> DepthAtFilmPixels(const std::vector<float>& depth, int width, int height, int w, int h)
{
  if (w == width && h == height)
    return depth;
  std::vector<float> at(static_cast<size_t>(w) * h);
  for (int row = 0; row < h; ++row)
    for (int x = 0; x < w; ++x)
    {
      const int fx = std::min(width - 1, static_cast<int>((x + 0.5) * width / w));
      const int fy = std::min(height - 1, static_cast<int>((row + 0.5) * height / h));
      at[static_cast<size_t>(row) * w + x] = depth[static_cast<size_t>(fy) * width + fx];
    }
  return at;
}

// Per pixel (rows top first, as the film): the distance along the camera
// ray to the geometry in the depth buffer, kInfinity where there is none.
// Perspective rays start at the camera, orthographic ones in the plane
// through it.
std::vector<float> CameraRayMaxDistance(vtkRenderer* ren, const std::vector<float>& depth, int width, int height)
{
  vtkCamera* camera = ren->GetActiveCamera();
  vtkNew<vtkMatrix4x4> inverse;
  inverse->DeepCopy(camera->GetCompositeProjectionTransformMatrix(ren->GetTiledAspectRatio(), -1, 1));
  inverse->Invert();
  const double* eye = camera->GetPosition();
  double dir[3];
  camera->GetDirectionOfProjection(dir);
  const bool parallel = camera->GetParallelProjection() != 0;
  std::vector<float> t(depth.size(), mmrtm::kInfinity);
  for (int row = 0; row < height; ++row)
    for (int x = 0; x < width; ++x)
    {
      const float z = depth[static_cast<size_t>(row) * width + x];
      if (z >= 1.f)
        continue;
      const double ndc[4] = { 2.0 * (x + 0.5) / width - 1.0, 2.0 * (row + 0.5) / height - 1.0, 2.0 * z - 1.0, 1.0 };
      double p[4];
      inverse->MultiplyPoint(ndc, p);
      double d[3], len2 = 0, along = 0;
      for (int k = 0; k < 3; ++k)
      {
        d[k] = p[k] / p[3] - eye[k];
        len2 += d[k] * d[k];
        along += d[k] * dir[k];
      }
      t[static_cast<size_t>(height - 1 - row) * width + x] = static_cast<float>(parallel ? along : std::sqrt(len2));
    }
  return t;
}

mmrtm::Affine3 ToAffine(vtkMatrix4x4* m)
{
  mmrtm::Affine3 a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      a.m[r][c] = static_cast<float>(m->GetElement(r, c));
  return a;
}

// The cropping regions of any flags but the subvolume's (ClipPlanes clips
// that one exactly), tested per point in the data's coordinates.
mmrtm::Scene::Cropping CroppingRegions(vtkVolumeMapper* mapper, vtkVolume* vol)
{
  mmrtm::Scene::Cropping cropping;
  if (!mapper->GetCropping() || mapper->GetCroppingRegionFlags() == VTK_CROP_SUBVOLUME)
    return cropping;
  vtkNew<vtkMatrix4x4> inverse;
  vol->GetMatrix(inverse);
  inverse->Invert();
  cropping.worldToData = ToAffine(inverse);
  cropping.keep = static_cast<uint32_t>(mapper->GetCroppingRegionFlags()) & mmrtm::Classifier::kNoCropping;
  const double* planes = mapper->GetCroppingRegionPlanes();
  for (int a = 0; a < 3; ++a)
  {
    cropping.lo[a] = static_cast<float>(planes[2 * a]);
    cropping.hi[a] = static_cast<float>(planes[2 * a + 1]);
  }
  return cropping;
}

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
// samples.
std::vector<double> TracingInputs(vtkMultiMaterialVolumeMapper* m, std::initializer_list<vtkMTimeType> held)
{
  std::vector<double> v = { static_cast<double>(m->GetSeed()), static_cast<double>(m->GetBackend()),
    static_cast<double>(m->GetGlobalIllumination()), m->GetShadowExtinctionScale(),
    static_cast<double>(m->GetMaximumBounces()), static_cast<double>(m->GetSampler()),
    static_cast<double>(m->GetAccelerator()), static_cast<double>(m->GetUnshadedScattering()),
    static_cast<double>(m->GetBlendMode()), static_cast<double>(m->GetAutoAdjustSampleDistances()),
    m->GetSampleDistance(), m->GetAverageIPScalarRange()[0], m->GetAverageIPScalarRange()[1],
    m->GetImageSampleDistance(), m->GetMinimumImageSampleDistance(), static_cast<double>(m->GetMaskType()),
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
  : Internal(new Internals)
{
}

vtkMultiMaterialVolumeMapper::~vtkMultiMaterialVolumeMapper()
{
  this->FinishPass(true);
  for (const auto& frame : this->Internal->PeelFrames)
    if (vtkRenderer* ren = frame->Renderer)
      ren->RemoveObserver(frame->Observer);
}

void vtkMultiMaterialVolumeMapper::FinishPass(bool cancel)
{
  Internals& in = *this->Internal;
  if (!in.InFlight)
    return;
  if (cancel)
    in.InFlight->Cancel = true;
  in.InFlight->Thread.join();
  if (!in.InFlight->Error.empty())
    vtkErrorMacro("Render: " << in.InFlight->Error);
  if (in.InFlight->Denoising)
    in.Display.Finished(std::move(in.InFlight->Denoised)); // the film is untouched
  else if (in.InFlight->Completed)
    in.Shown = std::make_unique<mmrtm::Film>(*in.Film);
  else
    in.Film.reset(); // a partial pass: the next render restarts
  in.InFlight.reset();
}

// Whether bringing the input up to date will run its producer (the test
// vtkDemandDrivenPipeline makes: data older than the pipeline's MTime).
bool vtkMultiMaterialVolumeMapper::InputWillExecute()
{
  vtkAlgorithm* producer = this->GetInputAlgorithm();
  vtkDataObject* data = this->GetInputDataObject(0, 0);
  auto* executive = producer ? vtkDemandDrivenPipeline::SafeDownCast(producer->GetExecutive()) : nullptr;
  if (!executive || !data)
    return true;
  executive->UpdatePipelineMTime();
  return data->GetUpdateTime() < executive->GetPipelineMTime();
}

const mmrtm::Film* vtkMultiMaterialVolumeMapper::ImageFilm()
{
  Internals& in = *this->Internal;
  return in.InFlight ? in.Shown.get() : in.Film.get();
}

bool vtkMultiMaterialVolumeMapper::IsRefining()
{
  return this->Internal->InFlight && !this->Internal->InFlight->Done;
}

void vtkMultiMaterialVolumeMapper::ResetAccumulation()
{
  this->FinishPass(true);
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
  const mmrtm::Film* film = this->ImageFilm();
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
  const mmrtm::Film* film = this->ImageFilm();
  return film && film->Samples() >= 2 ? film->Noise().relative : 0.0;
}

bool vtkMultiMaterialVolumeMapper::IsConverged()
{
  const mmrtm::Film* film = this->ImageFilm();
  if (!this->FilmConverged())
    return false;
  // The image shown is final once no denoise is running or due.
  Internals& in = *this->Internal;
  return !(in.InFlight && in.InFlight->Denoising) &&
    !(this->DenoisingApplies() && in.Display.Due(in.FilmGeneration, film->Samples(), false));
}

bool vtkMultiMaterialVolumeMapper::FilmConverged()
{
  const mmrtm::Film* film = this->ImageFilm();
  if (!film)
    return false;
  const int accumulated = static_cast<int>(film->Samples());
  if (this->MaximumSamples > 0 && accumulated >= this->MaximumSamples)
    return true;
  if (accumulated >= 1 && this->Internal->Scene.render.integrator.projection.mode != mmrtm::IntensityProjection::None)
    return true; // a projection's one sample is its image
  // The noise estimate needs two samples; it costs one pass over the film.
  return this->NoiseTarget > 0 && accumulated >= 2 && film->Noise().relative <= this->NoiseTarget;
}

void vtkMultiMaterialVolumeMapper::GetAccumulatedImage(vtkImageData* image)
{
  if (!image)
    return;
  image->Initialize();
  const mmrtm::Film* film = this->ImageFilm();
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
  const mmrtm::Film* film = this->ImageFilm();
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
  const mmrtm::Film* film = this->ImageFilm();
  if (film)
    in.Display.Recheck(*film, in.FilmGeneration);
  const mmrtm::DenoisedFilm* denoised =
    film && this->DenoisingApplies() ? in.Display.Shown(in.FilmGeneration, film->Samples()) : nullptr;
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
    this->RenderFrame(ren, vol);
  else if (this->TracesInThisFrame(ren))
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
      this->RenderFrame(ren, vol);
    }
    state->vtkglBlendEquation(static_cast<unsigned int>(equation));
    state->PopFramebufferBindings();
  }
  this->TimeToDraw = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  this->InvokeEvent(vtkCommand::VolumeMapperRenderEndEvent, nullptr);
}

bool vtkMultiMaterialVolumeMapper::TracesInThisFrame(vtkRenderer* ren)
{
  Internals& in = *this->Internal;
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
void vtkMultiMaterialVolumeMapper::RenderFrame(vtkRenderer* ren, vtkVolume* vol)
{
  Internals& in = *this->Internal;
  const auto start = std::chrono::steady_clock::now();
  auto draw = [&](const mmrtm::Film& film)
  {
    in.LastFilmSize[0] = film.Width();
    in.LastFilmSize[1] = film.Height();
    this->DrawFilm(ren, vol, film);
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
    const bool interactive = this->InteractiveAdjustResolution && window->GetDesiredUpdateRate() > 1.0;
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
    vtkErrorMacro("Render: " << e.what());
  }
}

bool vtkMultiMaterialVolumeMapper::ValidateInputs(vtkRenderer* ren, vtkVolume* vol, int viewport[4])
{
  Internals& in = *this->Internal;
  if (!this->GetInput() || !vol->GetProperty())
  {
    vtkErrorMacro("Render: " << (this->GetInput() ? "the vtkVolume has no volume property" : "no input"));
    return false;
  }
  ren->GetTiledSizeAndOrigin(&viewport[0], &viewport[1], &viewport[2], &viewport[3]);
  return viewport[0] > 0 && viewport[1] > 0;
}

vtkMultiMaterialVolumeMapper::InputState vtkMultiMaterialVolumeMapper::ReadInputs(
  vtkRenderer* ren, vtkVolume* vol, const int viewport[4])
{
  Internals& in = *this->Internal;
  InputState now;
  // The input brought up to date (a new or modified input rebuilds).
  this->GetInputAlgorithm()->UpdateInformation();
  this->GetInputAlgorithm()->Update();
  this->ReadTracedImage(now);
  now.Proxies.Mask = in.Mask;
  now.Proxies.MaskTime = in.Mask ? in.Mask->GetMTime() : 0;
  now.Proxies.MaskType = this->MaskType;
  now.Proxies.MultiMaterial = in.MultiMaterial;

  // The proxies the property asks for.
  vtkVolumeProperty* property = vol->GetProperty();
  const int components = now.Proxies.Scalars->GetNumberOfComponents();
  const bool independent = property->GetIndependentComponents() != 0;
  now.Proxies.Dependent = !independent && (components == 2 || components == 4) ? components : 0;
  now.Proxies.Independent = independent && components > 1 ? std::min(components, 4) : 0;
  // 4 dependent components fill the 4 proxies: no room for a gradient.
  const bool labels = in.Mask && this->MaskType == LABELMAP;
  // Isosurfaces of one component (the others render as composite).
  const bool isosurface = this->BlendMode == vtkVolumeMapper::ISOSURFACE_BLEND && !in.MultiMaterial;
  const bool isosurfaceComponents = isosurface && (now.Proxies.Dependent || now.Proxies.Independent);
  if (in.Warn("isosurface with components", isosurfaceComponents))
    vtkWarningMacro("isosurface blending of " << components << " components is not supported; rendering as composite");
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
    now.Materials.Options.isoSampleDistance = !this->AutoAdjustSampleDistances && this->SampleDistance > 0.f
      ? this->SampleDistance
      : static_cast<float>(std::min({ std::abs(spacing[0]), std::abs(spacing[1]), std::abs(spacing[2]) }));
  }
  // The projections show the colour they read as the albedo.
  const bool projection = this->BlendMode == vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND ||
    this->BlendMode == vtkVolumeMapper::MINIMUM_INTENSITY_BLEND ||
    this->BlendMode == vtkVolumeMapper::AVERAGE_INTENSITY_BLEND || this->BlendMode == vtkVolumeMapper::ADDITIVE_BLEND;
  now.Materials.Options.unshadedScatters = this->UnshadedScattering || projection;
  now.Materials.Options.localLighting = !this->GlobalIllumination;
  now.Proxies.NeedGradient = !in.MultiMaterial && now.Proxies.Dependent != 4 && !now.Proxies.Independent &&
    (mmrtm::NeedsGradientProxy(property, 0, labels) || now.Materials.Options.isosurface);
  now.Proxies.ComponentGradients = 0;
  for (int c = 0; c < now.Proxies.Independent; ++c)
    now.Proxies.ComponentGradients |= mmrtm::UsesGradientOpacity(property, c) ? 1 << c : 0;
  if (in.Warn("components", components > 4 && now.Proxies.Independent))
    vtkWarningMacro("only the first 4 of " << components << " independent components are rendered");
  if (in.Warn("mask with components", now.Proxies.Independent && in.Mask))
    vtkWarningMacro("with independent components, the mask is not used");

  now.Materials.Property = property;
  now.Materials.PropertyTime = PropertyMTime(property);
  now.Materials.MultiMaterialTime = in.MultiMaterial ? in.MultiMaterial->GetMTime() : 0;
  now.Materials.LabelMaterialsTime = in.LabelMaterialsTime();

  // Camera, lights, matrix, viewport (by value), clipping, the environment,
  // the opaque geometry (its depth), and the mapper's own settings.
  now.View.Width = viewport[0];
  now.View.Height = viewport[1];
  // VTK's still image: at the least distance when the distances adapt,
  // else at ImageSampleDistance; below 1 is 1 (samples cover a pixel).
  const double distance = std::max(1.0,
    static_cast<double>(
      this->AutoAdjustSampleDistances ? this->MinimumImageSampleDistance : this->ImageSampleDistance));
  now.View.FilmWidth = FilmSize(viewport[0], distance);
  now.View.FilmHeight = FilmSize(viewport[1], distance);
  now.View.Values = ViewSignature(ren, vol, now.View.FilmWidth, now.View.FilmHeight);
  now.View.Values.insert(
    now.View.Values.end(), { static_cast<double>(now.View.Width), static_cast<double>(now.View.Height) });
  now.View.Clip = this->ClipPlanes(vol);
  for (const mmrtm::ClipPlane& p : now.View.Clip)
    now.View.Values.insert(now.View.Values.end(), { p.normal.x, p.normal.y, p.normal.z, p.offset });
  this->UpdateEnvironment();
  now.View.Values.push_back(static_cast<double>(in.EnvironmentTime));
  now.View.Depth = ReadDepth(ren, viewport[0], viewport[1], viewport[2], viewport[3]);
  now.View.TracingTime = this->GetTracingMTime();
  now.View.Renderer = ren;
  now.View.Volume = vol;
  const int* tiles = ren->GetRenderWindow()->GetTileScale();
  now.View.Tile = tiles[0] > 1 || tiles[1] > 1;
  return now;
}

void vtkMultiMaterialVolumeMapper::ReadTracedImage(InputState& now)
{
  // The input as the tracer's image (mmrtmTracedImage.h), converted again
  // only when the input, its scalars or their modification times changed,
  // so that an unchanged input does not rebuild.
  Internals& in = *this->Internal;
  vtkDataSet* input = this->GetInput();
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(
    input, this->ScalarMode, this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag);
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
    vtkWarningMacro(<< c.Traced.Conversion << " (VTK's GPU mapper samples the grid on its own coordinates)");
}

vtkMultiMaterialVolumeMapper::Changes vtkMultiMaterialVolumeMapper::ChangesSince(
  const InputState& built, const InputState& now)
{
  Changes c;
  c.Proxies = !this->Internal->HasScene || !(now.Proxies == built.Proxies);
  const bool description = now.Proxies.MultiMaterial != nullptr;
  c.Description = description &&
    (now.Materials.MultiMaterialTime != built.Materials.MultiMaterialTime ||
      now.Materials.LabelMaterialsTime != built.Materials.LabelMaterialsTime);
  c.Materials = !description &&
    (now.Materials.Property != built.Materials.Property || now.Materials.PropertyTime != built.Materials.PropertyTime ||
      now.Materials.LabelMaterialsTime != built.Materials.LabelMaterialsTime ||
      !(now.Materials.Options == built.Materials.Options));
  c.View = !SameView(now.View.Values, built.View.Values) || now.View.Depth != built.View.Depth ||
    now.View.TracingTime != built.View.TracingTime;
  return c;
}

void vtkMultiMaterialVolumeMapper::UpdateProxies(const InputState& now)
{
  Internals& in = *this->Internal;
  in.HasScene = false; // until the rebuild succeeds
  const bool labels = now.Proxies.Mask && now.Proxies.MaskType == LABELMAP;
  const InputState::ProxyInputs& p = now.Proxies;
  this->BuildProxies(now.Materials.Property, p.Data, p.Scalars, p.Dependent, p.Independent, p.NeedGradient, labels);
  int64_t nans = 0;
  for (const mmrtm::HostVolume& v : in.Scene.proxies)
    nans += v.nanVoxelsReplaced;
  if (in.Warn("NaN voxels", nans > 0))
    vtkWarningMacro(<< nans
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

void vtkMultiMaterialVolumeMapper::UpdateDescription(const InputState& now)
{
  // An edited description over unchanged data: parsed again over the
  // proxies as they are, and refitted.
  this->ReparseMultiMaterialScene();
  this->Internal->Built.Materials.MultiMaterialTime = now.Materials.MultiMaterialTime;
  this->Internal->Built.Materials.LabelMaterialsTime = now.Materials.LabelMaterialsTime;
}

void vtkMultiMaterialVolumeMapper::UpdateMaterials(const InputState& now)
{
  // The transfer functions translated again (the scene's build refits).
  Internals& in = *this->Internal;
  if (const int nonFinite =
        mmrtm::SetMaterialsFromProperty(now.Materials.Property, 0, in.Layout, now.Materials.Options, in.Scene))
    vtkWarningMacro(<< "the volume property holds " << nonFinite
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

void vtkMultiMaterialVolumeMapper::UpdateView(vtkRenderer* ren, vtkVolume* vol, InputState& now)
{
  // A restart: a new film under the current camera, lights and settings.
  Internals& in = *this->Internal;
  vol->GetMatrix(in.Matrix);
  const mmrtm::Affine3 propMatrix = ToAffine(in.Matrix);
  for (size_t i = 0; i < in.Scene.proxies.size(); ++i)
    in.Scene.proxies[i].indexToWorld = mmrtm::AffineCompose(propMatrix, in.ImageIndexToWorld[i]);
  mmrtm::SetCameraFromVtk(ren->GetActiveCamera(), in.Scene);
  const int width = now.View.FilmWidth, height = now.View.FilmHeight;
  // Camera rays stop at opaque geometry: it hides the volume behind it,
  // and the volume in front of it hides it.
  in.Scene.cameraRayMaxDistance = now.View.Depth.empty()
    ? std::vector<float>()
    : CameraRayMaxDistance(
        ren, DepthAtFilmPixels(now.View.Depth, now.View.Width, now.View.Height, width, height), width, height);
  if (!in.LightsFromScene)
    mmrtm::SetLightsFromVtk(ren, now.Materials.Property, in.Scene);
  if (in.Environment)
    in.Scene.environment = in.Environment;
  in.Scene.clipPlanes = now.View.Clip;
  in.Scene.cropping = CroppingRegions(this, vol);
  mmrtm::RenderSettings& rs = in.Scene.render;
  rs.width = width;
  rs.height = height;
  rs.threads = this->NumberOfThreads;
  rs.exposure = static_cast<float>(this->Exposure);
  rs.integrator.seed = static_cast<uint64_t>(this->Seed);
  // Local lighting: shadow rays see (almost) nothing, and light scatters once.
  rs.integrator.shadowExtinctionScale =
    this->GlobalIllumination ? static_cast<float>(this->ShadowExtinctionScale) : kLocalLightingShadowScale;
  // Materials that only glow (unshaded, as VTK) need no light and no bounce.
  rs.integrator.maxBounces = !mmrtm::AnyMaterialScatters(in.Scene) ? 0
    : this->GlobalIllumination                                     ? this->MaximumBounces
                                                                   : 1;
  rs.integrator.sampler = this->Sampler == INDEPENDENT ? mmrtm::PixelSampler::Independent : mmrtm::PixelSampler::Sobol;
  rs.accelerator.kind = this->Accelerator == MACROCELL ? mmrtm::MajorantKind::Macrocell
    : this->Accelerator == NO_ACCELERATOR              ? mmrtm::MajorantKind::Global
                                                       : mmrtm::MajorantKind::Octree;
  rs.integrator.backgroundVisible = false; // VTK's background shows through
  rs.integrator.projection = this->Projection(now.Materials.Property);
  this->TakeFilm(now);
  in.Built.View = std::move(now.View);
  in.HasScene = true;
}

// The film for the view `now`: the parked one when it was made under this very
// view, else a new one (a restart). The film of the view before is parked
// when the view is a tile, or another renderer's or volume's view of this
// mapper, and the film before was neither a tile nor empty: after a
// magnified screenshot, and between the views of a mapper shared by two
// renderers, each view goes on accumulating.
void vtkMultiMaterialVolumeMapper::TakeFilm(const InputState& now)
{
  Internals& in = *this->Internal;
  const InputState::ViewInputs& view = now.View;
  const InputState::ViewInputs& before = in.Built.View;
  const bool otherView = view.Tile || view.Renderer != before.Renderer || view.Volume != before.Volume;
  std::unique_ptr<mmrtm::Film> previous = std::move(in.Film);
  const bool keepPrevious = otherView && previous && previous->Samples() > 0 && !before.Tile;
  const InputState::ViewInputs& parked = in.ParkedView;
  if (in.ParkedFilm && !view.Tile && SameView(view.Values, parked.Values) && view.Depth == parked.Depth &&
    view.TracingTime == parked.TracingTime && view.Renderer == parked.Renderer && view.Volume == parked.Volume)
  {
    in.Film = std::move(in.ParkedFilm);
  }
  else
  {
    in.Film = std::make_unique<mmrtm::Film>(view.FilmWidth, view.FilmHeight);
    in.Film->TrackDenoiserInputs();
    ++in.Restarts;
  }
  if (keepPrevious)
  {
    in.ParkedFilm = std::move(previous);
    in.ParkedView = before;
  }
  in.Shown.reset(); // the image of the view before
  ++in.FilmGeneration;
}

mmrtm::ProjectionSettings vtkMultiMaterialVolumeMapper::Projection(vtkVolumeProperty* property)
{
  // VTK's projection blend modes (mmrtm/projection.h), sampled as VTK's GPU
  // mapper samples them: with AutoAdjustSampleDistances on (its default) at
  // the smallest spacing of the volume in world space, else SampleDistance.
  Internals& in = *this->Internal;
  mmrtm::ProjectionSettings p;
  switch (this->BlendMode)
  {
    case vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND:
      p.mode = mmrtm::IntensityProjection::Maximum;
      break;
    case vtkVolumeMapper::MINIMUM_INTENSITY_BLEND:
      p.mode = mmrtm::IntensityProjection::Minimum;
      break;
    case vtkVolumeMapper::AVERAGE_INTENSITY_BLEND:
      p.mode = mmrtm::IntensityProjection::Average;
      break;
    case vtkVolumeMapper::ADDITIVE_BLEND:
      p.mode = mmrtm::IntensityProjection::Additive;
      break;
    default:
      return p; // composite (and isosurface, warned about): traced
  }
  const mmrtm::HostVolume& volume = in.Scene.proxies.at(0);
  float step = mmrtm::kInfinity;
  for (int axis = 0; axis < 3; ++axis)
  {
    const mmrtm::Affine3& m = volume.indexToWorld;
    step = std::min(
      step, std::sqrt(m.m[0][axis] * m.m[0][axis] + m.m[1][axis] * m.m[1][axis] + m.m[2][axis] * m.m[2][axis]));
  }
  p.step = step > 0.f ? step : 1.f;
  if (!this->AutoAdjustSampleDistances && this->SampleDistance > 0.f)
    p.step = this->SampleDistance;
  const double unit = property->GetScalarOpacityUnitDistance(0);
  p.opacityUnitDistance = unit > 0.0 ? static_cast<float>(unit) : 1.f;
  p.valueRange[0] = in.Layout.scalarRange[0]; // the input's (BuildProxies), not scanned per restart
  p.valueRange[1] = in.Layout.scalarRange[1];
  p.averageRange[0] = static_cast<float>(std::max<double>(this->AverageIPScalarRange[0], -FLT_MAX));
  p.averageRange[1] = static_cast<float>(std::min<double>(this->AverageIPScalarRange[1], FLT_MAX));
  return p;
}

void vtkMultiMaterialVolumeMapper::UpdateRenderer()
{
  Internals& in = *this->Internal;
  if (in.Renderer && in.RendererBackend == this->Backend && in.RendererThreads == this->NumberOfThreads)
    return;
  const mmrtm::Backend backend = this->Backend == CPU ? mmrtm::Backend::Cpu
    : this->Backend == CUDA                           ? mmrtm::Backend::Cuda
                                                      : mmrtm::Backend::Auto;
  in.Renderer = mmrtm::MakeRenderer(
    backend, this->NumberOfThreads, [this](const std::string& note) { vtkDebugMacro(<< note); });
  in.RendererBackend = this->Backend;
  in.RendererThreads = this->NumberOfThreads;
  in.BackendDescription = in.Renderer->Description();
}

mmrtm::SceneView vtkMultiMaterialVolumeMapper::BuildScene()
{
  // A new volume's summary build reads every voxel (14 s for 8 GiB on two
  // cores): VTK's ProgressEvent tells the application, on this thread.
  mmrtm::Scene& scene = this->Internal->Scene;
  scene.buildProgress = [this](double fraction) { this->UpdateProgress(fraction); };
  return scene.Build();
}

const mmrtm::Film* vtkMultiMaterialVolumeMapper::Refine(bool restart)
{
  // The scene's build refits only when what a refit reads changed, so a
  // render after a camera move keeps the majorants and takes microseconds.
  Internals& in = *this->Internal;
  const auto buildStart = std::chrono::steady_clock::now();
  const mmrtm::SceneView sceneView = this->BuildScene();
  if (in.Renderer) // a CUDA backend that fell back to the CPU says so
    in.BackendDescription = in.Renderer->Description();
  in.CountGridWork();
  if (in.Scene.ExtinctionWarning() != in.LastExtinctionWarning) // once per change, not per render
  {
    in.LastExtinctionWarning = in.Scene.ExtinctionWarning();
    if (!in.LastExtinctionWarning.empty())
      vtkWarningMacro(<< in.LastExtinctionWarning);
  }
  if (restart && (in.Scene.GridRefittedByLastBuild() || !in.Scene.Grid()))
    in.LastBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - buildStart).count();
  const int accumulated = static_cast<int>(in.Film->Samples());
  // A tile of a magnified screenshot is drawn once: with as many samples
  // as the view it magnifies has. A projection needs one.
  const bool projecting = in.Scene.render.integrator.projection.mode != mmrtm::IntensityProjection::None;
  const int perRender = projecting        ? 1
    : in.Built.View.Tile && in.ParkedFilm ? std::max(this->SamplesPerRender, static_cast<int>(in.ParkedFilm->Samples()))
                                          : this->SamplesPerRender;
  const int samples = this->FilmConverged() ? 0
    : this->MaximumSamples > 0              ? std::min(perRender, this->MaximumSamples - accumulated)
                                            : perRender;
  const bool background = this->AsynchronousRefinement && !restart && accumulated > 0 && in.Shown;
  if (background && this->DenoisingApplies() && in.Display.Due(in.FilmGeneration, in.Shown->Samples(), samples > 0) &&
    this->DenoiserReady())
  {
    // A denoise of the image shown, before more samples: on the thread of
    // the passes, so that this render returns at once.
    auto pass = std::make_unique<Internals::Pass>();
    Internals::Pass* p = pass.get();
    p->Denoising = true;
    auto snapshot = std::make_shared<mmrtm::FilmSnapshot>(mmrtm::SnapshotFilm(*in.Shown, in.FilmGeneration));
    const bool estimate = in.Display.WantsEstimate(in.FilmGeneration, in.Shown->Samples());
    mmrtm::Denoiser* denoiser = in.Denoiser.get();
    in.Display.Started();
    p->Thread = std::thread(
      [p, snapshot, estimate, denoiser]
      {
        try
        {
          p->Denoised = mmrtm::DenoiseSnapshot(*snapshot, estimate, true, mmrtm::OidnDenoise(*denoiser), &p->Cancel);
        }
        catch (const std::exception& e)
        {
          p->Error = e.what();
        }
        p->Done = true;
      });
    in.InFlight = std::move(pass);
    return in.Shown.get();
  }
  if (samples > 0)
    ++in.TracedPasses;
  if (samples > 0 && background)
  {
    // The next pass on a thread of its own, under in.Built; this render
    // draws the last finished image.
    auto pass = std::make_unique<Internals::Pass>();
    Internals::Pass* p = pass.get();
    mmrtm::Renderer* renderer = in.Renderer.get();
    mmrtm::Film* film = in.Film.get();
    const mmrtm::Scene* scene = &in.Scene;
    p->Thread = std::thread(
      [p, renderer, film, scene, sceneView, samples]
      {
        try
        {
          p->Completed = renderer->Render(*scene, sceneView, *film, samples, nullptr, nullptr, &p->Cancel);
        }
        catch (const std::exception& e)
        {
          p->Error = e.what();
        }
        p->Done = true;
      });
    in.InFlight = std::move(pass);
    return in.Shown.get();
  }
  if (samples > 0)
    in.Renderer->Render(in.Scene, sceneView, *in.Film, samples, nullptr, nullptr);
  if (this->AsynchronousRefinement)
    in.Shown = std::make_unique<mmrtm::Film>(*in.Film);
  else if (this->DenoisingApplies() && in.Display.Due(in.FilmGeneration, in.Film->Samples(), !this->FilmConverged()) &&
    this->DenoiserReady())
  {
    // Synchronous refinement: the denoise after the pass, in this render.
    in.Display.Started();
    std::optional<mmrtm::DenoisedFilm> denoised;
    try
    {
      denoised = mmrtm::DenoiseSnapshot(mmrtm::SnapshotFilm(*in.Film, in.FilmGeneration),
        in.Display.WantsEstimate(in.FilmGeneration, in.Film->Samples()), true, mmrtm::OidnDenoise(*in.Denoiser));
    }
    catch (const std::exception& e)
    {
      vtkErrorMacro("Render: the denoiser failed: " << e.what());
    }
    in.Display.Finished(std::move(denoised));
  }
  return in.Film.get();
}

bool vtkMultiMaterialVolumeMapper::DenoisingApplies()
{
  // A projection's one sample is its image: there is no noise to take out.
  return this->DenoisingMode != DENOISING_OFF &&
    this->Internal->Scene.render.integrator.projection.mode == mmrtm::IntensityProjection::None;
}

bool vtkMultiMaterialVolumeMapper::DenoiserReady()
{
  Internals& in = *this->Internal;
  if (!in.Denoiser && !in.DenoiserLoadTried)
  {
    in.DenoiserLoadTried = true;
    try
    {
      in.Denoiser = mmrtm::Denoiser::Load(this->NumberOfThreads);
    }
    catch (const mmrtm::DenoiserError& e)
    {
      // Said once in full; the status names it while a denoising mode is on.
      const std::string why = e.what();
      in.Display.SetUnavailable(why.substr(0, why.find(" (")));
      vtkWarningMacro(<< why);
    }
  }
  return in.Denoiser != nullptr;
}

// The proxies of the input (its components as the property uses them), the
// gradient magnitude when some function reads it, and the mask.
void vtkMultiMaterialVolumeMapper::BuildProxies(vtkVolumeProperty* property, vtkImageData* input, vtkDataArray* scalars,
  int dependent, int independent, bool needGradient, bool labels)
{
  Internals& in = *this->Internal;
  vtkImageData* mask = independent ? nullptr : in.Mask.Get();
  mmrtm::Scene& scene = in.Scene;
  scene.proxies.clear();
  in.ImageIndexToWorld.clear();
  in.Layout = mmrtm::ProxyLayout();
  auto component = [&](int c, const char* name)
  {
    scene.proxies.push_back(mmrtm::ImageDataToHostVolume(input, scalars, c, name, mmrtm::Interpolation::Trilinear));
    return static_cast<int>(scene.proxies.size()) - 1;
  };
  component(0, dependent == 4 ? "red" : "scalars");
  in.Layout.scalarRange = scene.proxies[0].ValueRange();
  scene.gradientProxy = 0;
  if (independent)
  {
    in.Layout.independent = independent;
    in.Layout.componentRanges[0] = in.Layout.scalarRange;
    for (int c = 1; c < independent; ++c)
      in.Layout.componentRanges[c] = scene.proxies[component(c, "component")].ValueRange();
    // Gradient magnitudes of the components with gradient opacity, while
    // there is room among the proxies.
    for (int c = 0; c < independent; ++c)
    {
      if (!mmrtm::UsesGradientOpacity(property, c))
        continue;
      if (scene.proxies.size() >= static_cast<size_t>(mmrtm::kMaxProxies))
      {
        vtkWarningMacro("no room for the gradient of component " << c << ": its gradient opacity is not used");
        continue;
      }
      in.Layout.componentGradient[c] = static_cast<int>(scene.proxies.size());
      scene.proxies.push_back(mmrtm::GradientMagnitudeProxy(scene.proxies[c], "gradient"));
      in.Layout.componentGradientRanges[c] = scene.proxies.back().ValueRange();
    }
  }
  if (dependent == 2)
  {
    in.Layout.opacity = component(1, "opacity");
  }
  else if (dependent == 4)
  {
    in.Layout.rgb[0] = 0;
    in.Layout.rgb[1] = component(1, "green");
    in.Layout.rgb[2] = component(2, "blue");
    in.Layout.opacity = component(3, "opacity");
    float top = 0.f;
    for (int c = 0; c < 3; ++c)
      top = std::max(top, scene.proxies[c].ValueRange()[1]);
    in.Layout.colorScale = scalars->GetDataType() == VTK_UNSIGNED_CHAR ? 255.f : std::max(top, 1e-6f);
  }
  if (in.Layout.opacity >= 0)
  {
    in.Layout.opacityRange = scene.proxies[in.Layout.opacity].ValueRange();
    scene.gradientProxy = in.Layout.opacity; // VTK shades dependent data by the opacity component
  }
  if (needGradient)
  {
    const int source = scene.gradientProxy;
    in.Layout.gradient = static_cast<int>(scene.proxies.size());
    scene.proxies.push_back(mmrtm::GradientMagnitudeProxy(scene.proxies[source], "gradient"));
    in.Layout.gradientRange = scene.proxies.back().ValueRange();
  }
  if (mask)
  {
    // Labels are never interpolated; a mask on another grid is put on
    // the input's by nearest neighbour in world space.
    mmrtm::HostVolume m =
      mmrtm::ImageDataToHostVolume(mask, nullptr, 0, labels ? "label map" : "mask", mmrtm::Interpolation::Nearest);
    m = mmrtm::AlignLabelsToVolume(std::move(m), scene.proxies[0]);
    (labels ? in.Layout.labels : in.Layout.binaryMask) = static_cast<int>(scene.proxies.size());
    scene.proxies.push_back(std::move(m));
  }
  if (scene.proxies.size() > mmrtm::kMaxProxies)
    throw mmrtm::InputError("this combination of components, gradient opacity and mask needs " +
      std::to_string(scene.proxies.size()) + " proxy volumes; at most " + std::to_string(mmrtm::kMaxProxies) +
      " are supported");
}

void vtkMultiMaterialVolumeMapper::UpdateEnvironment()
{
  Internals& in = *this->Internal;
  vtkTexture* texture = in.EnvironmentTexture;
  vtkImageData* image = texture ? vtkImageData::SafeDownCast(texture->GetInput()) : nullptr;
  if (texture && texture->GetInputAlgorithm())
  {
    texture->GetInputAlgorithm()->Update();
    image = vtkImageData::SafeDownCast(texture->GetInput());
  }
  const vtkMTimeType time = image ? std::max(image->GetMTime(), texture->GetMTime()) : 0;
  if (time == in.EnvironmentTime && this->EnvironmentIntensity == in.EnvironmentScale)
    return;
  in.EnvironmentTime = time;
  in.EnvironmentScale = this->EnvironmentIntensity;
  in.Environment.reset();
  if (!image)
    return;
  vtkDataArray* a = image->GetPointData()->GetScalars();
  const int* d = image->GetDimensions();
  if (!a || a->GetNumberOfComponents() < 3 || d[2] != 1 || d[0] < 1 || d[1] < 1)
  {
    vtkErrorMacro("the environment texture needs a 2D image with 3 or 4 components");
    return;
  }
  // sRGB bytes to linear; float data is radiance already. VTK's rows run
  // bottom up, the environment's from the zenith down.
  const bool bytes = a->GetDataType() == VTK_UNSIGNED_CHAR;
  auto linear = [bytes](double v)
  {
    if (!bytes)
      return static_cast<float>(std::max(v, 0.0));
    v /= 255.0;
    return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
  };
  std::vector<mmrtm::RGB> texels(static_cast<size_t>(d[0]) * d[1]);
  const float scale = static_cast<float>(this->EnvironmentIntensity);
  for (int y = 0; y < d[1]; ++y)
    for (int x = 0; x < d[0]; ++x)
    {
      const vtkIdType i = x + static_cast<vtkIdType>(d[0]) * (d[1] - 1 - y);
      texels[static_cast<size_t>(y) * d[0] + x] = mmrtm::RGB(linear(a->GetComponent(i, 0)) * scale,
        linear(a->GetComponent(i, 1)) * scale, linear(a->GetComponent(i, 2)) * scale);
    }
  in.Environment = std::make_shared<mmrtm::EnvironmentMap>(d[0], d[1], std::move(texels));
}

void vtkMultiMaterialVolumeMapper::ParseMultiMaterialScene()
{
  // The description over the mapper's volumes: its input as "scalars" (and
  // the mask as "labels"); the camera and image size stay VTK's. The
  // labels' looks (SetLabelMaterial) are classes of the description's
  // label materials, ahead of its own.
  Internals& in = *this->Internal;
  nlohmann::json doc = in.MultiMaterial->GetScene();
  doc.erase("camera");
  doc.erase("volumes"); // a description's own files are not the mapper's data
  if (in.Layout.labels >= 0)
    doc = mmrtm::WithLabelLooks(std::move(doc), in.LabelLooksWithParameters());
  mmrtm::SceneInputs inputs;
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

void vtkMultiMaterialVolumeMapper::ReparseMultiMaterialScene()
{
  // The description is parsed over the proxies of the last build (the
  // input and the mask, moved with their buffers and given back their own
  // index-to-world: the volume's matrix is applied at the restart). The
  // grid's summaries go over to the new scene when its proxies are those
  // very buffers, so that the edit costs a refit.
  Internals& in = *this->Internal;
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

std::vector<mmrtm::ClipPlane> vtkMultiMaterialVolumeMapper::ClipPlanes(vtkVolume* vol)
{
  std::vector<mmrtm::ClipPlane> planes;
  // Clipping planes, in world space: the side the normal points to is kept.
  if (this->ClippingPlanes)
  {
    this->ClippingPlanes->InitTraversal();
    while (vtkPlane* plane = this->ClippingPlanes->GetNextItem())
    {
      const double* n = plane->GetNormal();
      const double* o = plane->GetOrigin();
      mmrtm::ClipPlane p;
      p.normal = { static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2]) };
      p.offset = static_cast<float>(-(n[0] * o[0] + n[1] * o[1] + n[2] * o[2]));
      planes.push_back(p);
    }
  }
  // Subvolume cropping, in the data's coordinates (before the volume's
  // matrix): six axis-aligned half-spaces, taken to world space through the
  // inverse transpose of the matrix.
  if (this->Cropping && this->CroppingRegionFlags == VTK_CROP_SUBVOLUME)
  {
    vtkNew<vtkMatrix4x4> inverse;
    vol->GetMatrix(inverse);
    inverse->Invert();
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side)
      {
        // Data space: sign * (x[axis] - bound) >= 0.
        const double sign = side == 0 ? 1.0 : -1.0, bound = this->CroppingRegionPlanes[2 * axis + side];
        double n[3], d = -sign * bound;
        for (int c = 0; c < 3; ++c)
          n[c] = sign * inverse->GetElement(axis, c);
        d += sign * inverse->GetElement(axis, 3);
        mmrtm::ClipPlane p;
        p.normal = { static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2]) };
        p.offset = static_cast<float>(d);
        planes.push_back(p);
      }
  }
  const bool tooMany = static_cast<int>(planes.size()) > mmrtm::kMaxClipPlanes;
  if (this->Internal->Warn("clipping planes", tooMany))
    vtkWarningMacro("only " << mmrtm::kMaxClipPlanes << " clipping and cropping planes are used");
  if (tooMany)
    planes.resize(mmrtm::kMaxClipPlanes);
  return planes;
}

double vtkMultiMaterialVolumeMapper::RenderPreview(vtkRenderer* ren, int width, int height)
{
  Internals& in = *this->Internal;
  const double distance = this->AutoAdjustSampleDistances
    ? in.PreviewDistance
    : std::max(1.0, static_cast<double>(this->ImageSampleDistance));
  const int w = FilmSize(width, distance), h = FilmSize(height, distance);
  mmrtm::RenderSettings& rs = in.Scene.render;
  rs.width = w;
  rs.height = h;
  const std::vector<float>& fullDepth = in.Built.View.Depth;
  if (!fullDepth.empty())
    in.Scene.cameraRayMaxDistance = CameraRayMaxDistance(ren, DepthAtFilmPixels(fullDepth, width, height, w, h), w, h);
  const mmrtm::SceneView view = this->BuildScene();
  in.CountGridWork();
  in.Preview = std::make_unique<mmrtm::Film>(w, h);
  const auto start = std::chrono::steady_clock::now();
  in.Renderer->Render(in.Scene, view, *in.Preview, 1, nullptr, nullptr);
  ++in.TracedPasses;
  // Denoised on its colour alone, at OIDN's fast quality: one sample's
  // guides are as noisy as its colour, and the frame has a budget.
  in.PreviewDenoised.reset();
  if (this->DenoisingApplies() && this->DenoiserReady())
  {
    const auto denoiseStart = std::chrono::steady_clock::now();
    in.Denoiser->SetQuality(mmrtm::Denoiser::Quality::Fast);
    try
    {
      in.PreviewDenoised =
        mmrtm::DenoiseSnapshot(mmrtm::SnapshotFilm(*in.Preview, 0), false, false, mmrtm::OidnDenoise(*in.Denoiser));
    }
    catch (const mmrtm::DenoiserError& e)
    {
      vtkErrorMacro("Render: the denoiser failed: " << e.what());
    }
    in.Denoiser->SetQuality(mmrtm::Denoiser::Quality::Balanced);
    in.PreviewDenoiseSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - denoiseStart).count();
    ++in.PreviewDenoises;
  }
  // The still render after the interaction starts again at full resolution.
  in.Film.reset();
  ++in.InteractiveRenders;
  // The denoise scales with the pixels as the tracing does (AdaptPreview).
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void vtkMultiMaterialVolumeMapper::AdaptPreview(double seconds, double tracedSeconds, double budgetSeconds)
{
  // The tracing time scales with the film's pixels, 1 / distance^2; the
  // rest of the frame (reading the inputs and the depth, drawing) is taken
  // as fixed. The distance that would have fit the budget, averaged
  // (geometrically) with the one used, so that one noisy frame does not
  // swing the next.
  Internals& in = *this->Internal;
  if (!this->AutoAdjustSampleDistances)
    return;
  const double least = std::max(1.0, static_cast<double>(this->MinimumImageSampleDistance));
  const double most = std::max(least, static_cast<double>(this->MaximumImageSampleDistance));
  const double d = in.PreviewDistance;
  const double forTracing = std::max(0.1 * budgetSeconds, budgetSeconds - (seconds - tracedSeconds));
  const double fits = d * std::sqrt(std::max(tracedSeconds, 1e-6) / forTracing);
  in.PreviewDistance = std::min(most, std::max(least, std::sqrt(d * fits)));
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
  else if (&film == this->ImageFilm())
  {
    in.LastShown = Internals::ShownImage::Film;
    in.Display.Recheck(film, in.FilmGeneration);
    const mmrtm::DenoisedFilm* shown =
      this->DenoisingApplies() ? in.Display.Shown(in.FilmGeneration, film.Samples()) : nullptr;
    if (shown)
    {
      denoised = &shown->image;
      denoisedAlpha = &shown->alpha;
    }
    else if (this->DenoisingApplies() && in.PreviewDenoised && in.PreviewStandsFor == in.FilmGeneration &&
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
