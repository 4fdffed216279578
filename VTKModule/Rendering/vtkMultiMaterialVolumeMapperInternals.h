// The mapper's internals (private to MMRTM::Rendering): what it keeps
// between renders, the record of the inputs it made them from, and the
// phases of a render, one unit each:
//   vtkMultiMaterialVolumeMapper.cxx             the API, Render and its frame, drawing
//   vtkMultiMaterialVolumeMapperInputs.cxx       reading the inputs, the proxies, the materials
//   vtkMultiMaterialVolumeMapperView.cxx         reading the view, the film it restarts, previews
//   vtkMultiMaterialVolumeMapperEnvironment.cxx  the environment texture as the tracer's map
//   vtkMultiMaterialVolumeMapperRefinement.cxx   adding samples, the refinement thread, denoising
#ifndef vtkMultiMaterialVolumeMapperInternals_h
#define vtkMultiMaterialVolumeMapperInternals_h

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkRayCastImageDisplayHelper.h>
#include <vtkSmartPointer.h>
#include <vtkTexture.h>
#include <vtkTimeStamp.h>
#include <vtkWeakPointer.h>

#include "denoised_display.h"
#include "denoiser.h"
#include "environment_map.h"
#include "film.h"
#include "label_materials.h"
#include "mmrtmTracedImage.h"
#include "mmrtmVtkSceneTranslation.h"
#include "render_backend.h"
#include "scene.h"
#include "scene_json.h"
#include "vtkMultiMaterialProperty.h"
#include "vtkMultiMaterialVolumeMapper.h"

// What the mapper keeps between renders, and the inputs it was made from.
struct vtkMultiMaterialVolumeMapper::Internals
{
  explicit Internals(vtkMultiMaterialVolumeMapper* self)
    : Self(self)
  {
  }
  vtkMultiMaterialVolumeMapper* const Self; // its settings, its input, its drawing

  // What a render reads, in three parts, each of which decides one phase's
  // work: the proxies (voxels, mask, the components the property uses), the
  // materials (the property, the multi-material description, the label
  // parameters) and the view (camera, lights, viewport, clipping, opaque
  // geometry, environment, the mapper's tracing settings). Modification
  // times where VTK keeps them; the view by value (SameView).
  struct InputState
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
                 this->MultiMaterial, this->Dependent, this->Independent, this->ComponentGradients,
                 this->NeedGradient) ==
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
  struct Changes
  {
    bool Proxies = false;     // made again from the input (and the description parsed over them)
    bool Description = false; // the description parsed again over the proxies as they are
    bool Materials = false;   // the property translated again
    bool View = false;        // the camera, lights and settings set again
    bool Any() const { return this->Proxies || this->Description || this->Materials || this->View; }
  };

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

  // A frame (vtkMultiMaterialVolumeMapper.cxx): the phases below, as far
  // as the inputs changed, then drawing.
  void RenderFrame(vtkRenderer* ren, vtkVolume* vol);
  bool TracesInThisFrame(vtkRenderer* ren);

  // The inputs and the scene made from them (...Inputs.cxx).
  bool ValidateInputs(vtkRenderer* ren, vtkVolume* vol, int viewport[4]);
  InputState ReadInputs(vtkRenderer* ren, vtkVolume* vol, const int viewport[4]);
  void ReadTracedImage(InputState& now); // the input as the tracer's image (part of ReadInputs)
  Changes ChangesSince(const InputState& built, const InputState& now);
  void UpdateProxies(const InputState& now);
  void ParseMultiMaterialScene();
  void ReparseMultiMaterialScene();
  void UpdateDescription(const InputState& now);
  void UpdateMaterials(const InputState& now);
  void UpdateRenderer();
  mmrtm::SceneView BuildScene(); // the scene's Build, its summary build reported as VTK progress

  // The view and the film it restarts (...View.cxx).
  void ReadView(vtkRenderer* ren, vtkVolume* vol, const int viewport[4], InputState::ViewInputs& view);
  static bool SameViewInputs(const InputState::ViewInputs& a, const InputState::ViewInputs& b);
  std::vector<mmrtm::ClipPlane> ClipPlanes(vtkVolume* vol);
  void UpdateView(vtkRenderer* ren, vtkVolume* vol, InputState& now);
  mmrtm::ProjectionSettings Projection(vtkVolumeProperty* property);
  void TakeFilm(const InputState& now);
  double RenderPreview(vtkRenderer* ren, int width, int height); // the tracing's seconds
  void AdaptPreview(double seconds, double tracedSeconds, double budgetSeconds);

  // The environment texture as the tracer's map (...Environment.cxx).
  void UpdateEnvironment();

  // Adding samples, on this thread or the refinement thread, and the
  // denoised display (...Refinement.cxx).
  const mmrtm::Film* Refine(bool restart);
  void StartPass(bool denoising, std::function<void(Pass&)> work); // in flight on a thread of its own
  void FinishPass(bool cancel);
  bool InputWillExecute();
  const mmrtm::Film* ImageFilm();
  bool FilmConverged();    // the accumulation has reached MaximumSamples or NoiseTarget
  bool DenoisingApplies(); // a denoising mode, and noise to take out (not a projection)
  bool DenoiserReady();    // loads it at the first call
};

#endif
