/**
 * @class   vtkMRMLMultiMaterialVolumeRenderingDisplayNode
 * @brief   volume rendering display node of the MM-RTM path tracer
 *
 * The display node of the Volume Rendering module's rendering method "Path
 * tracing (MM-RTM)". As Slicer's CPU and GPU ray cast nodes, it refers to a
 * volume, its volume property node (presets included) and an ROI; it adds
 * what the path tracer needs: how samples accumulate (per render, at most,
 * or until a noise target), the light transport (bounces, shadow-ray
 * extinction scale), the accelerator and backend, an optional MM-RTM material
 * preset or scene description, and a segmentation whose segments are
 * rendered as distinct materials (their colour, 3D opacity and visibility,
 * with optional surface parameters per segment).
 *
 * The displayable manager pipeline vtkMRMLMultiMaterialVolumeRenderingPipeline
 * (SlicerLayerDM) renders it with vtkMultiMaterialVolumeMapper; Slicer's own
 * volume rendering displayable manager ignores the class. Everything is
 * saved in the scene (WriteXML / ReadXML), so a saved scene reloads to the
 * same render for the same seed.
 */
#ifndef vtkMRMLMultiMaterialVolumeRenderingDisplayNode_h
#define vtkMRMLMultiMaterialVolumeRenderingDisplayNode_h

#include "vtkSlicerMultiMaterialVolumeRenderingModuleMRMLExport.h"

#include <vtkMRMLVolumeRenderingDisplayNode.h>

#include <map>    // for std::map
#include <string> // for std::string

class vtkMRMLSegmentationNode;
class vtkStringArray;

class VTK_SLICER_MULTIMATERIALVOLUMERENDERING_MODULE_MRML_EXPORT vtkMRMLMultiMaterialVolumeRenderingDisplayNode
  : public vtkMRMLVolumeRenderingDisplayNode
{
public:
  static vtkMRMLMultiMaterialVolumeRenderingDisplayNode* New();
  vtkTypeMacro(vtkMRMLMultiMaterialVolumeRenderingDisplayNode, vtkMRMLVolumeRenderingDisplayNode);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Lets any MRML scene create this node by its class name, through VTK's
  /// object factory (vtkMRMLScene::CreateNodeByClass asks it for classes
  /// that scene has not registered): Volume Rendering's logic can then make
  /// this method's display node even in a scene where this module's logic
  /// was never registered (trame-slicer), instead of dereferencing the null
  /// node it got before. Idempotent; importing mmrtm_slicer calls it.
  static void RegisterNodeFactory();

  vtkMRMLNode* CreateNodeInstance() override;
  const char* GetNodeTagName() override { return "MultiMaterialVolumeRendering"; }
  void ReadXMLAttributes(const char** atts) override;
  void WriteXML(ostream& of, int indent) override;
  /// vtkMRMLVolumeRenderingDisplayNode copies with the old-style Copy(); both
  /// paths copy this class's settings.
  void Copy(vtkMRMLNode* node) override;
  vtkMRMLCopyContentMacro(vtkMRMLMultiMaterialVolumeRenderingDisplayNode);

  ///@{
  /// Samples per pixel added by each render (default 4).
  vtkSetClampMacro(SamplesPerRender, int, 1, 65536);
  vtkGetMacro(SamplesPerRender, int);
  ///@}

  ///@{
  /// Samples per pixel after which refinement stops (default 256; 0: no limit).
  vtkSetClampMacro(MaximumSamples, int, 0, VTK_INT_MAX);
  vtkGetMacro(MaximumSamples, int);
  ///@}

  ///@{
  /// Refinement in the background (default off;
  /// vtkMultiMaterialVolumeMapper::AsynchronousRefinement): a render
  /// returns at once with the last finished image while the next pass runs
  /// on the tracer's threads, so that an application's event loop (a web
  /// server streaming frames) stays free between passes.
  vtkSetMacro(AsynchronousRefinement, bool);
  vtkGetMacro(AsynchronousRefinement, bool);
  vtkBooleanMacro(AsynchronousRefinement, bool);
  ///@}

  ///@{
  /// Relative noise of the image at which refinement stops (default 0: no
  /// noise target; vtkMultiMaterialVolumeMapper::NoiseTarget).
  vtkSetClampMacro(NoiseTarget, double, 0.0, 1.0);
  vtkGetMacro(NoiseTarget, double);
  ///@}

  ///@{
  /// Real scattering events per path (default 32; 1 is single scattering).
  vtkSetClampMacro(MaximumBounces, int, 0, 1024);
  vtkGetMacro(MaximumBounces, int);
  ///@}

  ///@{
  /// Shadow-ray extinction scale in (0, 1] (default 0.8, the paper's
  /// artistic choice; 1 is unbiased).
  vtkSetClampMacro(ShadowExtinctionScale, double, 0.01, 1.0);
  vtkGetMacro(ShadowExtinctionScale, double);
  ///@}

  enum Accelerators
  {
    Octree = 0,
    Macrocell,
    NoAccelerator,
    Accelerator_Last
  };
  ///@{
  /// Majorant accelerator (default Octree).
  vtkSetClampMacro(Accelerator, int, Octree, Accelerator_Last - 1);
  vtkGetMacro(Accelerator, int);
  static const char* GetAcceleratorAsString(int id);
  static int GetAcceleratorFromString(const char* name);
  ///@}

  enum Backends
  {
    Auto = 0,
    CPU,
    CUDA,
    Backend_Last
  };
  ///@{
  /// Where the tracer runs (default Auto: CUDA when a device is present).
  vtkSetClampMacro(Backend, int, Auto, Backend_Last - 1);
  vtkGetMacro(Backend, int);
  static const char* GetBackendAsString(int id);
  static int GetBackendFromString(const char* name);
  ///@}

  enum DenoisingModes
  {
    DenoisingOff = 0,
    DenoisingAuto,
    DenoisingAlways,
    DenoisingMode_Last
  };
  ///@{
  /// What the 3D view shows (vtkMultiMaterialVolumeMapper::DenoisingMode;
  /// default Auto): the image denoised while that is estimated closer to
  /// the truth, and noise-free previews while the view is dragged (Auto),
  /// always denoised (Always), or the unbiased accumulation (Off). The
  /// accumulation is the same either way, and a change keeps it.
  vtkSetClampMacro(DenoisingMode, int, DenoisingOff, DenoisingMode_Last - 1);
  vtkGetMacro(DenoisingMode, int);
  static const char* GetDenoisingModeAsString(int id);
  static int GetDenoisingModeFromString(const char* name);
  ///@}

  ///@{
  /// Seed of the random numbers (default 0): one seed and sample count
  /// give one image.
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// An MM-RTM material preset (ct-bone, ct-soft-tissue, ct-organs, ...:
  /// vtkMultiMaterialProperty::SetPreset) that replaces the translation of
  /// the volume property; empty (default): the volume property is rendered.
  vtkSetStdStringFromCharMacro(MaterialPreset);
  vtkGetCharFromStdStringMacro(MaterialPreset);
  ///@}

  ///@{
  /// MM-RTM scene JSON merged over the preset (or alone, when no preset is
  /// set), as vtkMultiMaterialProperty::MergeSceneJSON; empty by default.
  vtkSetStdStringFromCharMacro(SceneJSON);
  vtkGetCharFromStdStringMacro(SceneJSON);
  ///@}

  ///@{
  /// A segmentation whose segments are materials of their own, on the
  /// volume's grid: each visible segment in its colour and 3D opacity
  /// (the rest of the volume keeps the volume property's look). Null: none.
  void SetAndObserveSegmentationNodeID(const char* segmentationNodeId);
  const char* GetSegmentationNodeID();
  vtkMRMLSegmentationNode* GetSegmentationNode();
  ///@}

  ///@{
  /// Surface and phase parameters of one segment's material (JSON:
  /// "roughness", "metallic", "surface_probability", "anisotropy",
  /// "emission"; vtkMultiMaterialVolumeMapper::SetLabelMaterialParameters).
  /// Null or empty removes them.
  void SetSegmentMaterialParameters(const char* segmentId, const char* json);
  const char* GetSegmentMaterialParameters(const char* segmentId);
  void GetSegmentIDsWithMaterialParameters(vtkStringArray* segmentIds);
  void RemoveAllSegmentMaterialParameters();
  ///@}

  /// Reference role of the segmentation.
  static const char* GetSegmentationNodeReferenceRole() { return "segmentation"; }

protected:
  vtkMRMLMultiMaterialVolumeRenderingDisplayNode();
  ~vtkMRMLMultiMaterialVolumeRenderingDisplayNode() override;
  vtkMRMLMultiMaterialVolumeRenderingDisplayNode(const vtkMRMLMultiMaterialVolumeRenderingDisplayNode&) = delete;
  void operator=(const vtkMRMLMultiMaterialVolumeRenderingDisplayNode&) = delete;

  /// Segment edits, colours, visibility and opacity of the segmentation
  /// (events of the segmentation node and its display node) modify this
  /// node, so that the views update.
  void ProcessMRMLEvents(vtkObject* caller, unsigned long event, void* callData) override;

  int SamplesPerRender = 4;
  int MaximumSamples = 256;
  double NoiseTarget = 0.0;
  bool AsynchronousRefinement = false;
  int MaximumBounces = 32;
  double ShadowExtinctionScale = 0.8;
  int Accelerator = Octree;
  int Backend = Auto;
  int DenoisingMode = DenoisingAuto;
  int Seed = 0;
  std::string MaterialPreset;
  std::string SceneJSON;
  std::map<std::string, std::string> SegmentMaterialParameters;
};

#endif
