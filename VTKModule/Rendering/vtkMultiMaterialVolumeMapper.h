/**
 * @class   vtkMultiMaterialVolumeMapper
 * @brief   physically based volume rendering with the MM-RTM path tracer
 *
 * vtkMultiMaterialVolumeMapper renders a vtkImageData with the multi-material
 * radiative transfer model of Xu et al. 2025: an unbiased volumetric path
 * tracer (delta tracking, multiple scattering, surface scattering on the
 * gradient normal) accelerated by a hierarchical majorant grid. It maps the
 * vtkVolumeProperty of the volume onto the tracer's transfer functions by
 * the rules of Documentation/vtk-mapper.md, takes its lights from the
 * renderer, and accumulates samples progressively: every Render() adds
 * SamplesPerRender samples per pixel until MaximumSamples, and any change
 * restarts the accumulation with the least work that change needs:
 *
 * - new or modified input data: the scene and the majorant grid's summaries
 *   are rebuilt (GetNumberOfSceneBuilds());
 * - a change of the volume property or of one of its transfer functions: the
 *   transfer functions are translated again and the grid refitted
 *   (GetNumberOfRefits());
 * - a change of the camera, a light, the viewport or the volume's matrix:
 *   the accumulation restarts (GetNumberOfRestarts());
 * - the exposure, the tone mapping, the denoised display: the accumulated
 *   samples are drawn again, not restarted;
 * - the samples per render, the maximum samples, the noise target, the
 *   threads, asynchronous refinement: the accumulation goes on from the
 *   samples it has (none of them changes the converged image);
 * - nothing changed: samples are added.
 *
 * The volume's matrix (vtkProp3D) is honoured, so oblique orientations and
 * non-uniform scales render correctly. The image is composited premultiplied
 * in front of everything else in the viewport: camera rays stop at the
 * opaque geometry VTK drew first (its depth buffer), so where that geometry
 * is in front the image is transparent. With the renderer's depth peeling
 * for volumes (SetUseDepthPeelingForVolumes) the image is traced once per
 * frame and drawn under all translucent geometry, which VTK's peeling then
 * blends over it (it cannot be peeled: the tracer's film has no depth
 * layers).
 *
 * Clipping planes (world space) and cropping (data space, every region
 * set) limit what is seen. The maximum, minimum and average intensity and
 * additive blend modes are projections, as VTK's GPU mapper computes them;
 * the isosurface blend mode traces surfaces at the property's iso-values
 * (each as opaque as the scalar opacity there), lit as the rest. Not
 * supported yet (a warning is given once per cause): isosurfaces of data
 * with several components (rendered as composite), more than four
 * independent components, gradient opacity of independent components
 * beyond the four proxies.
 *
 * @sa vtkVolumeMapper vtkFixedPointVolumeRayCastMapper
 */
#ifndef vtkMultiMaterialVolumeMapper_h
#define vtkMultiMaterialVolumeMapper_h

#include "mmrtmRenderingModule.h" // for export macro
#include "vtkVolumeMapper.h"

#include <memory> // for std::unique_ptr

class vtkDataArray;
class vtkIdList;
class vtkImageData;
class vtkVolumeProperty;
class vtkMultiMaterialProperty;
class vtkTexture;
namespace mmrtm
{
class Film;
}

class MMRTMRENDERING_EXPORT vtkMultiMaterialVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkMultiMaterialVolumeMapper* New();
  vtkTypeMacro(vtkMultiMaterialVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Samples per pixel added by each Render() (default 4). A change keeps
   * the samples accumulated.
   */
  vtkSetClampMacro(SamplesPerRender, int, 1, 65536);
  vtkGetMacro(SamplesPerRender, int);
  ///@}

  ///@{
  /**
   * Samples per pixel after which Render() only redraws the image
   * (default 256; 0 accumulates without limit). A change keeps the samples
   * accumulated: raised, refinement goes on from them; lowered below them,
   * the image keeps them all.
   */
  vtkSetClampMacro(MaximumSamples, int, 0, VTK_INT_MAX);
  vtkGetMacro(MaximumSamples, int);
  ///@}

  ///@{
  /**
   * Relative noise of the accumulated image (Film noise: the root mean
   * square standard error of the pixels' luminance over their mean
   * luminance, measured by the difference between each pixel's even and
   * odd samples) at which Render() stops adding samples, as it does at
   * MaximumSamples; 0 (the default) has no noise target. A change keeps
   * the samples accumulated.
   */
  vtkSetClampMacro(NoiseTarget, double, 0.0, 1.0);
  vtkGetMacro(NoiseTarget, double);
  ///@}

  ///@{
  /**
   * Seed of the random numbers (default 0). Renders of one seed and sample
   * count are identical at any thread count.
   */
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /**
   * CPU threads, 0 for all (default 0). A change keeps the samples
   * accumulated (the image does not depend on the thread count).
   */
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  enum Backends
  {
    AUTO = 0,
    CPU = 1,
    CUDA = 2
  };
  ///@{
  /**
   * AUTO (default) uses CUDA when a device is present, else the CPU.
   */
  vtkSetClampMacro(Backend, int, AUTO, CUDA);
  vtkGetMacro(Backend, int);
  void SetBackendToAuto() { this->SetBackend(AUTO); }
  void SetBackendToCPU() { this->SetBackend(CPU); }
  void SetBackendToCUDA() { this->SetBackend(CUDA); }
  ///@}

  enum Accelerators
  {
    OCTREE = 0,
    MACROCELL = 1,
    NO_ACCELERATOR = 2
  };
  ///@{
  /**
   * The majorant accelerator of the free-path sampling: OCTREE (default,
   * the paper's hierarchical grid), MACROCELL (its leaf level alone) or
   * NO_ACCELERATOR (one global majorant, a baseline). All are unbiased.
   */
  vtkSetClampMacro(Accelerator, int, OCTREE, NO_ACCELERATOR);
  vtkGetMacro(Accelerator, int);
  void SetAcceleratorToOctree() { this->SetAccelerator(OCTREE); }
  void SetAcceleratorToMacrocell() { this->SetAccelerator(MACROCELL); }
  void SetAcceleratorToNone() { this->SetAccelerator(NO_ACCELERATOR); }
  ///@}

  enum Samplers
  {
    SOBOL = 0,
    INDEPENDENT = 1
  };
  ///@{
  /**
   * Where the first numbers of each pixel sample come from: SOBOL (default;
   * Owen-scrambled Sobol' pairs for the pixel position and the first two
   * scattering events, which reach a given error sooner) or INDEPENDENT
   * (every number from the sample's random stream). Both are unbiased, and
   * GetRelativeNoise() is the error of either: it compares a pixel's even
   * samples with its odd ones, two independently scrambled nets. (A pixel's
   * own sample variance overstates a SOBOL image's error, so the mapper's
   * z-score tests use INDEPENDENT.)
   */
  vtkSetClampMacro(Sampler, int, SOBOL, INDEPENDENT);
  vtkGetMacro(Sampler, int);
  void SetSamplerToSobol() { this->SetSampler(SOBOL); }
  void SetSamplerToIndependent() { this->SetSampler(INDEPENDENT); }
  ///@}

  ///@{
  /**
   * Real scattering events per path (default 32): 1 is single scattering
   * (the lights' direct light only), 0 emission and absorption only.
   */
  vtkSetClampMacro(MaximumBounces, int, 0, 1024);
  vtkGetMacro(MaximumBounces, int);
  ///@}

  ///@{
  /**
   * Refine on a thread of its own (default off). With it on, the first pass
   * after a change renders in Render() as always, so the image shows the
   * change at once; the passes after it run in the background while
   * Render() draws the last finished pass and returns at once, so that an
   * application's event loop stays responsive. A render that finds
   * anything changed stops the pass in flight (between 16 x 16 tiles) and
   * restarts. The images are the same as without it (one seed, one sample
   * count). IsRefining() says whether a pass (or a denoise) is in flight:
   * an application renders again a little later to pick up its samples.
   */
  vtkSetMacro(AsynchronousRefinement, vtkTypeBool);
  vtkGetMacro(AsynchronousRefinement, vtkTypeBool);
  vtkBooleanMacro(AsynchronousRefinement, vtkTypeBool);
  bool IsRefining();
  ///@}

  ///@{
  /**
   * Exposure multiplier before tone mapping (default 1, at least 0). A
   * change redraws the samples accumulated so far; it does not start the
   * accumulation again.
   */
  vtkSetClampMacro(Exposure, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Exposure, double);
  ///@}

  ///@{
  /**
   * How the accumulated radiance becomes pixel values. OFF: the value
   * itself, clipped at 1, as VTK's mappers write their colours (the colour
   * functions hold display values, so a white surface facing VTK's
   * headlight shows its colour times Diffuse). FILMIC: the ACES filmic
   * curve and the sRGB encoding, soft highlights for scenes lit beyond 1
   * (environment maps, several lights, emission). AUTOMATIC (the default):
   * off for a translated vtkVolumeProperty; with a vtkMultiMaterialProperty
   * its description's "tone_mapper" (filmic unless it says otherwise, as in
   * mmrtm-render: the presets are made for it). Like the exposure, a change
   * redraws the samples accumulated so far. The projection blend modes show
   * VTK's colours either way.
   */
  enum ToneMappings
  {
    AUTOMATIC_TONE_MAPPING = 0,
    TONE_MAPPING_OFF = 1,
    FILMIC_TONE_MAPPING = 2
  };
  vtkSetClampMacro(ToneMapping, int, AUTOMATIC_TONE_MAPPING, FILMIC_TONE_MAPPING);
  vtkGetMacro(ToneMapping, int);
  void SetToneMappingToAutomatic() { this->SetToneMapping(AUTOMATIC_TONE_MAPPING); }
  void SetToneMappingToOff() { this->SetToneMapping(TONE_MAPPING_OFF); }
  void SetToneMappingToFilmic() { this->SetToneMapping(FILMIC_TONE_MAPPING); }
  ///@}

  ///@{
  /**
   * What a volume property's Shade off means. Off (the default), as in
   * VTK's mappers: the colour glows, unlit (emission and absorption: no
   * light, no shadow, no bounce). On: the colour is the albedo of volume
   * scattering (an isotropic phase function), lit by the renderer's lights
   * with shadows and multiple scattering. Shade on is lit either way (a
   * surface on the gradient normal). A change translates the property again.
   */
  vtkSetMacro(UnshadedScattering, vtkTypeBool);
  vtkGetMacro(UnshadedScattering, vtkTypeBool);
  vtkBooleanMacro(UnshadedScattering, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Global illumination (default on): the path tracer's light transport,
   * shadows (shadow rays through the volume) and light scattered many
   * times (up to MaximumBounces). Off: VTK's local lighting, each point lit
   * by the lights directly, unshadowed, light scattered once, which is what
   * VTK's mappers compute with shading on: the colours come within VTK's
   * own (translucent tissue no longer darkened by the light's way in).
   */
  vtkSetMacro(GlobalIllumination, vtkTypeBool);
  vtkGetMacro(GlobalIllumination, vtkTypeBool);
  vtkBooleanMacro(GlobalIllumination, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Looks: SetLookToVTK (the default) gives VTK's colours: automatic
   * tone mapping (off for a vtkVolumeProperty), unshaded volumes glow.
   * SetLookToFilmic is the path tracer's own: filmic tone mapping, unshaded
   * volumes scatter the lights. Neither changes GlobalIllumination.
   */
  void SetLookToVTK();
  void SetLookToFilmic();
  ///@}

  ///@{
  /**
   * Shadow-ray extinction scale in (0, 1] (default 0.8, the paper's; 1 is
   * unbiased).
   */
  vtkSetClampMacro(ShadowExtinctionScale, double, 0.01, 1.0);
  vtkGetMacro(ShadowExtinctionScale, double);
  ///@}

  ///@{
  /**
   * A mask on the input's grid (or, resampled by nearest neighbour, on any
   * grid that overlaps it in world space), as in vtkGPUVolumeRayCastMapper.
   * LABELMAP (the default): every label with a colour, scalar-opacity or
   * gradient-opacity function in the volume property (SetLabelColor, ...)
   * becomes a material of its own where the mask has that label, as in
   * VTK's GPU mapper: its functions alone (a function it lacks is
   * component 0's), so a label whose opacity is 0 is empty; label 0 and
   * labels without functions take the property's component-0 functions.
   * BINARY: voxels where the mask is 0 are empty.
   */
  void SetMaskInput(vtkImageData* mask);
  vtkImageData* GetMaskInput();
  enum MaskTypes
  {
    BINARY = 0,
    LABELMAP = 1
  };
  vtkSetClampMacro(MaskType, int, BINARY, LABELMAP);
  vtkGetMacro(MaskType, int);
  void SetMaskTypeToBinary() { this->SetMaskType(BINARY); }
  void SetMaskTypeToLabelMap() { this->SetMaskType(LABELMAP); }
  ///@}

  ///@{
  /**
   * With a LABELMAP mask: label `label` shown as a material by the one
   * label rule (GetLabelDensityAtFullOpacity): its colour (0 to 1) the
   * albedo, its opacity (0 to 1) times 2.5 per mm the extinction, no
   * gradient opacity, shading from the volume property, surface parameters
   * from SetLabelMaterialParameters. It takes the place of the property's
   * label functions for that label; a label without one keeps them (or,
   * without those, shows the property's own functions). Over a
   * multi-material description (SetMultiMaterialProperty) it is a class of
   * the description's "label_materials" of its own, ahead of the
   * description's classes. The looks are compared by value: setting the
   * same values again, or removing the labels and setting them again as
   * they were, changes nothing. Values outside [0, 1] are an error at the
   * next render. 3D Slicer's segments, ParaView's label-map array and the
   * viewer's label list reach the mapper this way.
   */
  void SetLabelMaterial(int label, double r, double g, double b, double opacity);
  // The label's colour and opacity in rgbo; false (rgbo untouched) without one.
  bool GetLabelMaterial(int label, double rgbo[4]);
  void RemoveLabelMaterial(int label);
  void RemoveAllLabelMaterials();
  ///@}

  ///@{
  /**
   * With a LABELMAP mask: surface and phase parameters of label `label`'s
   * material, which VTK's label functions cannot say (its colour, opacity
   * and gradient opacity stay the property's or SetLabelMaterial's; over a
   * multi-material description, only a label given SetLabelMaterial takes
   * them). `json` is an object with
   * any of "roughness", "metallic", "surface_probability" (0 to 1),
   * "anisotropy" (-1 to 1) and "emission" ([r, g, b]); an unknown key or a
   * value out of range is an error at the next render. A null or empty
   * `json` removes the label's parameters. 3D Slicer's segments use this.
   */
  void SetLabelMaterialParameters(int label, const char* json);
  const char* GetLabelMaterialParameters(int label);
  void RemoveAllLabelMaterialParameters();
  ///@}

  ///@{
  /**
   * Materials, BSDF parameters, material transfer functions, lights and
   * presets beyond what vtkVolumeProperty can say. When set, it replaces the
   * translation of the volume property (whose functions are then not used);
   * null (the default) translates the volume property.
   */
  void SetMultiMaterialProperty(vtkMultiMaterialProperty* property);
  vtkMultiMaterialProperty* GetMultiMaterialProperty();
  ///@}

  ///@{
  /**
   * An environment light: an equirectangular image (its input vtkImageData,
   * 3 or 4 components; float data is linear radiance, unsigned char is
   * sRGB), the top row toward +z (superior), times EnvironmentIntensity. It
   * replaces the ambient term, and is lit in addition to the lights. Null
   * (the default): no environment texture.
   */
  void SetEnvironmentTexture(vtkTexture* texture);
  vtkTexture* GetEnvironmentTexture();
  vtkSetClampMacro(EnvironmentIntensity, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(EnvironmentIntensity, double);
  ///@}

  enum DenoisingModes
  {
    DENOISING_OFF = 0,
    DENOISING_AUTO = 1,
    DENOISING_ALWAYS = 2
  };
  ///@{
  /**
   * What the view shows of the accumulation (Documentation/denoising.md).
   * OFF (the default, so that regression images stay unbiased): the
   * accumulated film. AUTO: the film denoised by Intel Open Image Denoise
   * while that is estimated closer to the truth than the film (from the
   * film's two independent halves), then the film. ALWAYS: the denoised
   * film. Either way the accumulation goes on underneath, the same to the
   * bit, and a change of mode keeps it. The denoiser is guided by the
   * albedo and normal where the camera rays first collide, gathered with
   * the samples; it runs after a pass, at most a quarter of the time, on
   * the refinement thread with AsynchronousRefinement. Interactive
   * previews are denoised too (colour only), and after one (the end of a
   * drag, a front end's preview of a change) the denoised preview stays
   * until the first denoised image of the new accumulation. Without the
   * library the film is shown and GetDisplayStatus says why. The
   * projection blend modes are never denoised (their one sample is their
   * image).
   */
  virtual void SetDenoisingMode(int mode);
  vtkGetMacro(DenoisingMode, int);
  void SetDenoisingModeToOff() { this->SetDenoisingMode(DENOISING_OFF); }
  void SetDenoisingModeToAuto() { this->SetDenoisingMode(DENOISING_AUTO); }
  void SetDenoisingModeToAlways() { this->SetDenoisingMode(DENOISING_ALWAYS); }
  ///@}

  /**
   * What the last frame showed: "denoised, 8 samples", "unbiased, 64
   * samples, noise 2.1 %", "preview, denoised", with the reason where a
   * denoising mode could not denoise ("not denoised: ...").
   */
  const char* GetDisplayStatus();

  /**
   * Whether the last frame drawn showed a denoised image.
   */
  bool IsDenoisedImageShown();

  /**
   * What a frame drawn now would show of the accumulation: the denoised
   * image or the film (GetAccumulatedImage), linear RGB and alpha as that
   * gives the film's; emptied before the first sample. An interactive
   * preview is not kept.
   */
  void GetDisplayedImage(vtkImageData* image);

  ///@{
  /**
   * The denoised display's costs and estimates: denoiser runs and their
   * seconds since construction (previews included), and, for the
   * accumulation shown, Auto's latest estimates of the relative RMS error
   * of the denoised image and of the film when they were made (-1 when
   * none was made).
   */
  int GetNumberOfDenoises();
  double GetDenoisingSeconds();
  double GetLastDenoiseSeconds();
  double GetEstimatedDenoisedError();
  double GetEstimatedFilmError();
  ///@}

  ///@{
  /**
   * While the render window asks for an interactive frame rate (its
   * DesiredUpdateRate above 1, as vtkRenderWindowInteractor sets it while
   * the camera moves), render a preview: 1 sample per pixel at a fraction of
   * the resolution that adapts to the frame budget, without touching the
   * accumulation. When the camera stops (the still update rate), the
   * accumulation starts again at full resolution. Default on.
   */
  vtkSetMacro(InteractiveAdjustResolution, vtkTypeBool);
  vtkGetMacro(InteractiveAdjustResolution, vtkTypeBool);
  vtkBooleanMacro(InteractiveAdjustResolution, vtkTypeBool);
  ///@}

  ///@{
  /**
   * VTK's image sample distances (vtkGPUVolumeRayCastMapper's names,
   * meanings and defaults; vtkVolumeMapper does not declare them): the
   * film's pixel is ImageSampleDistance viewport pixels wide (1, the
   * default: one film pixel per viewport pixel; 2: a film of half the
   * width and height, stretched over the viewport). Values below 1 render
   * as 1: the tracer's samples per pixel already cover the pixel.
   *
   * AutoAdjustSampleDistances on (the default): a still render is at
   * MinimumImageSampleDistance (1) and ImageSampleDistance is not used, as
   * in VTK's GPU mapper; an interactive preview (see
   * InteractiveAdjustResolution) adapts its distance between
   * MinimumImageSampleDistance (1) and MaximumImageSampleDistance (10) so
   * that a frame takes the volume's AllocatedRenderTime (which VTK's
   * renderer sets from the window's DesiredUpdateRate, divided among the
   * props). Off: still renders and previews are at ImageSampleDistance.
   * A change restarts the accumulation only when it changes the still
   * film's size.
   */
  vtkSetClampMacro(ImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(ImageSampleDistance, float);
  vtkSetClampMacro(MinimumImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(MinimumImageSampleDistance, float);
  vtkSetClampMacro(MaximumImageSampleDistance, float, 0.1f, 100.0f);
  vtkGetMacro(MaximumImageSampleDistance, float);
  vtkSetClampMacro(AutoAdjustSampleDistances, vtkTypeBool, 0, 1);
  vtkGetMacro(AutoAdjustSampleDistances, vtkTypeBool);
  vtkBooleanMacro(AutoAdjustSampleDistances, vtkTypeBool);
  ///@}

  ///@{
  /**
   * VTK's distance between samples along a ray (world units, default 1,
   * as in vtkGPUVolumeRayCastMapper). It does not affect the path tracer:
   * delta and ratio tracking sample free paths exactly, without a step.
   * The projection blend modes (maximum, minimum, average intensity,
   * additive) step by it when AutoAdjustSampleDistances is off, else by the
   * volume's smallest voxel spacing, as VTK's GPU mapper does. A change
   * restarts the accumulation.
   */
  vtkSetMacro(SampleDistance, float);
  vtkGetMacro(SampleDistance, float);
  ///@}

  /**
   * The size (width, height) of the last film drawn: the accumulation's,
   * or an interactive preview's. The viewport's size divided by the image
   * sample distance in use (see ImageSampleDistance), rounded up.
   */
  void GetLastFilmSize(int size[2]);

  /**
   * Discards the accumulated samples; the next Render() starts again.
   */
  void ResetAccumulation();

  /**
   * Samples per pixel accumulated so far.
   */
  int GetAccumulatedSamples();

  /**
   * The relative noise of the accumulated image (see NoiseTarget); 0 before
   * two samples have accumulated.
   */
  double GetRelativeNoise();

  /**
   * Whether the accumulation has reached MaximumSamples or NoiseTarget and
   * the image shown is final (no denoise is due or running), so that
   * Render() only redraws: an application refining while idle stops asking
   * for renders then.
   */
  bool IsConverged();

  /**
   * The accumulated image before exposure and tone mapping: per pixel the
   * mean linear radiance (RGB) and coverage (alpha), 4 float components,
   * row 0 at the bottom as in VTK images. The image is emptied when nothing
   * has accumulated yet. Renders of one seed and sample count give the same
   * values at any thread count.
   */
  void GetAccumulatedImage(vtkImageData* image);

  ///@{
  /**
   * How often the scene was rebuilt (data), refitted (transfer functions)
   * and the accumulation restarted (any change), since construction.
   */
  int GetNumberOfSceneBuilds();
  int GetNumberOfRefits();
  int GetNumberOfRestarts();
  int GetNumberOfInteractiveRenders();
  ///@}

  /**
   * When what the mapper traces last changed, compared by value: its
   * settings that the traced image depends on (seed, bounces, sampler,
   * accelerator, backend, blend mode, SampleDistance, cropping, clipping
   * planes, environment intensity) and the times of what it holds (mask,
   * multi-material property, label materials, environment texture). A
   * setting that keeps the samples (exposure, tone mapping, denoising,
   * samples per render, maximum samples, noise target, threads,
   * asynchronous refinement) does not change it, nor does a setting set
   * again to its value. Each render restarts when it changed (or the view
   * did); a front end that renders a preview for a change asks it whether
   * the mapper changed.
   */
  vtkMTimeType GetTracingMTime();

  /**
   * How often the tracer ran: a still render that added samples, an
   * interactive preview, or a pass started on the refinement thread. A
   * frame traces at most once, however often VTK calls Render() in it (with
   * depth peeling for volumes VTK calls it once per peel), and a render that
   * only redraws (converged, or a further call in the same frame) does not
   * trace.
   */
  int GetNumberOfTracedPasses();

  /**
   * How often the majorant grid's per-voxel summaries were built (the
   * costly part of a scene build; a refit does not build them). An edited
   * vtkMultiMaterialProperty over unchanged data reuses them.
   */
  int GetNumberOfMajorantGridBuilds();

  /**
   * How often the majorant grid's majorants were refitted: after a change
   * of what the refit reads (the transfer functions, the materials, the
   * data), not after a camera, light or settings change.
   */
  int GetNumberOfMajorantGridRefits();

  /**
   * Seconds the scene's build took the last time it refitted the
   * majorants: after a transfer-function change (with the grid's summaries
   * after a data change). A camera move or a settings edit does not refit.
   * For status lines and benchmarks.
   */
  double GetLastRefitSeconds();

  /**
   * The colour of a label that nothing else names a colour for (no colour
   * table, no segment colour): the one default of the front ends (the
   * viewer's label list, ParaView's label-map array), well apart for
   * neighbouring labels; label 0, the background, is black.
   */
  static void GetDefaultLabelColor(int label, double rgb[3]);

  /**
   * The labels a label map holds: the distinct non-zero values of its
   * scalars (one component), ascending, put in `labels`. The front ends'
   * one scan (the viewer's label list, ParaView's label-map array). False,
   * with `labels` empty and a warning naming the problem, for scalars that
   * are missing, not one component, or not integers.
   */
  static bool GetLabelsPresent(vtkImageData* labelMap, vtkIdList* labels);

  /**
   * The extinction per millimetre of a label shown at opacity 1 (2.5: as
   * opaque as the organs of the ct-organs preset): the one density rule by
   * which front ends turn a label's opacity into a material (Slicer's
   * segments, the viewer's label list).
   */
  static double GetLabelDensityAtFullOpacity();

  /**
   * Description of the backend in use ("cpu, 2 thread(s)", "cuda, ..."):
   * after a render, what rendered its scene.
   */
  const char* GetBackendDescription();

  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkMultiMaterialVolumeMapper();
  ~vtkMultiMaterialVolumeMapper() override;

  int SamplesPerRender = 4;
  int MaximumSamples = 256;
  int Seed = 0;
  int NumberOfThreads = 0;
  int Backend = AUTO;
  double Exposure = 1.0;
  int ToneMapping = AUTOMATIC_TONE_MAPPING;
  vtkTypeBool UnshadedScattering = 0;
  vtkTypeBool GlobalIllumination = 1;
  double NoiseTarget = 0.0;
  vtkTypeBool AsynchronousRefinement = 0;
  int Accelerator = OCTREE;
  int Sampler = SOBOL;
  int MaximumBounces = 32;
  double ShadowExtinctionScale = 0.8;
  int MaskType = LABELMAP;
  vtkTypeBool InteractiveAdjustResolution = 1;
  float ImageSampleDistance = 1.0f;
  float MinimumImageSampleDistance = 1.0f;
  float MaximumImageSampleDistance = 10.0f;
  vtkTypeBool AutoAdjustSampleDistances = 1;
  float SampleDistance = 1.0f;
  double EnvironmentIntensity = 1.0;
  int DenoisingMode = DENOISING_OFF;

  /**
   * Draws a film into the viewport (tone-mapped, premultiplied). Render()
   * draws through this hook: the accumulated film of a still render, or
   * the preview or last finished pass of the interactive and asynchronous
   * modes. Sample-parallel rendering (the ParaView plugin under MPI)
   * overrides it to combine the films of all processes first.
   */
  virtual void DrawFilm(vtkRenderer* ren, vtkVolume* vol, const mmrtm::Film& film);

private:
  vtkMultiMaterialVolumeMapper(const vtkMultiMaterialVolumeMapper&) = delete;
  void operator=(const vtkMultiMaterialVolumeMapper&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
