/**
 * @class   vtkMRMLMultiMaterialVolumeRenderingPipeline
 * @brief   renders a vtkMRMLMultiMaterialVolumeRenderingDisplayNode in a 3D view
 *
 * A SlicerLayerDM pipeline, one per (3D view, display node): a vtkVolume with
 * a vtkMultiMaterialVolumeMapper in the view's main renderer (render order
 * 0, so that the depth of Slicer's models and markups composites with the
 * volume both ways). From MRML it takes
 * - the volume's image data, placed by its IJK-to-RAS matrix and every
 *   (linear) parent transform;
 * - the volume property node's vtkVolumeProperty, which the mapper
 *   translates (presets included) as it translates any VTK volume property;
 * - the ROI, when cropping is on, as six clipping planes in world space;
 * - the display node's visibility in this view (IsDisplayableInView);
 * - the render settings, material preset and segmentation of the node
 *   (vtkSlicerMultiMaterialVolumeRenderingLogic does the translation).
 *
 * While the view is idle the image refines: after each render that did
 * not converge (MaximumSamples or NoiseTarget) the pipeline asks for
 * another render; any change restarts the accumulation with the least work
 * (vtkMultiMaterialVolumeMapper). Graphics resources are released when the
 * pipeline leaves its renderer.
 *
 * RegisterPipelineCreator() adds the creator to LayerDM's pipeline factory
 * (the package does this when it is imported; the Slicer module at setup).
 */
#ifndef vtkMRMLMultiMaterialVolumeRenderingPipeline_h
#define vtkMRMLMultiMaterialVolumeRenderingPipeline_h

#include "vtkSlicerMultiMaterialVolumeRenderingModuleMRMLDisplayableManagerExport.h"

#include <vtkMRMLLayerDMPipeline.h>

#include <memory> // for std::unique_ptr

class vtkMultiMaterialVolumeMapper;
class vtkVolume;

class VTK_SLICER_MULTIMATERIALVOLUMERENDERING_MODULE_MRMLDISPLAYABLEMANAGER_EXPORT
  vtkMRMLMultiMaterialVolumeRenderingPipeline : public vtkMRMLLayerDMPipeline
{
public:
  static vtkMRMLMultiMaterialVolumeRenderingPipeline* New();
  vtkTypeMacro(vtkMRMLMultiMaterialVolumeRenderingPipeline, vtkMRMLLayerDMPipeline);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Adds, once, a creator to vtkMRMLLayerDMPipelineFactory::GetInstance()
  /// that makes this pipeline for a 3D view node and a
  /// vtkMRMLMultiMaterialVolumeRenderingDisplayNode. Returns true the first
  /// time.
  static bool RegisterPipelineCreator();

  /// The mapper and volume this pipeline renders with (for tests and
  /// scripts: their images, counters and samples).
  vtkMultiMaterialVolumeMapper* GetMapper();
  vtkVolume* GetVolume();

  void SetDisplayNode(vtkMRMLNode* displayNode) override;
  void UpdateFromMRML() override;
  void OnRendererAdded(vtkRenderer* renderer) override;
  void OnRendererRemoved(vtkRenderer* renderer) override;

protected:
  vtkMRMLMultiMaterialVolumeRenderingPipeline();
  ~vtkMRMLMultiMaterialVolumeRenderingPipeline() override;
  vtkMRMLMultiMaterialVolumeRenderingPipeline(const vtkMRMLMultiMaterialVolumeRenderingPipeline&) = delete;
  void operator=(const vtkMRMLMultiMaterialVolumeRenderingPipeline&) = delete;

  void OnUpdate(vtkObject* object, unsigned long eventId, void* callData) override;

private:
  void UpdateObservedNodes();
  void UpdateGeometry();
  void UpdateProperty();
  void UpdateCropping();
  void OnRenderEnd();

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
