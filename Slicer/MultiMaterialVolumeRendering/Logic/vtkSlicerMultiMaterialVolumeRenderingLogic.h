/**
 * @class   vtkSlicerMultiMaterialVolumeRenderingLogic
 * @brief   the path tracer as a rendering method of Slicer's Volume Rendering module
 *
 * Registers vtkMRMLMultiMaterialVolumeRenderingDisplayNode with the scene and
 * the rendering method "Path tracing (MM-RTM)" with the Volume Rendering
 * logic, so that it is in the module's method list and
 * vtkSlicerVolumeRenderingLogic::CreateDefaultVolumeRenderingNodes creates it
 * when it is the default. In Slicer the module finds the Volume Rendering
 * logic at setup; elsewhere (the PyPI Slicer core) call
 * SetVolumeRenderingLogic once.
 *
 * It also holds what the displayable manager pipeline does with MRML,
 * static and free of rendering state, so that a script can do the same:
 * - the display node's settings onto a vtkMultiMaterialVolumeMapper;
 * - a segmentation onto the volume's grid as a label map, one label per
 *   segment;
 * - each visible segment's colour and 3D opacity as label functions of a
 *   vtkVolumeProperty, which the mapper renders as a material of its own
 *   (its translation of the volume property is the only one: nothing here
 *   makes transfer functions of its own).
 */
#ifndef vtkSlicerMultiMaterialVolumeRenderingLogic_h
#define vtkSlicerMultiMaterialVolumeRenderingLogic_h

#include "vtkSlicerMultiMaterialVolumeRenderingModuleLogicExport.h"

#include <vtkSlicerModuleLogic.h>
#include <vtkWeakPointer.h>

class vtkImageData;
class vtkMRMLMultiMaterialVolumeRenderingDisplayNode;
class vtkMultiMaterialProperty;
class vtkMultiMaterialVolumeMapper;
class vtkSlicerVolumeRenderingLogic;
class vtkStringArray;
class vtkVolumeProperty;

class VTK_SLICER_MULTIMATERIALVOLUMERENDERING_MODULE_LOGIC_EXPORT vtkSlicerMultiMaterialVolumeRenderingLogic
  : public vtkSlicerModuleLogic
{
public:
  static vtkSlicerMultiMaterialVolumeRenderingLogic* New();
  vtkTypeMacro(vtkSlicerMultiMaterialVolumeRenderingLogic, vtkSlicerModuleLogic);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The name in the Volume Rendering module's method list.
  static const char* GetRenderingMethodName() { return "Path tracing (MM-RTM)"; }

  ///@{
  /// The Volume Rendering logic the method is registered with. Setting it
  /// registers the method (once per logic).
  void SetVolumeRenderingLogic(vtkSlicerVolumeRenderingLogic* logic);
  vtkSlicerVolumeRenderingLogic* GetVolumeRenderingLogic();
  ///@}

  /// Whether the Volume Rendering logic lists the method (its method list
  /// is a std::map, out of Python's reach).
  bool IsRenderingMethodRegistered();

  /// Puts the node's render settings on the mapper: samples per render,
  /// maximum samples, noise target, bounces, shadow extinction scale,
  /// accelerator, backend, seed. Unchanged values change nothing.
  static void ApplyRenderSettings(
    vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkMultiMaterialVolumeMapper* mapper);

  /// Fills `materials` from the node's MaterialPreset and SceneJSON and
  /// returns true, or returns false when the node has neither (the volume
  /// property is rendered then). A bad preset or JSON is an error naming it.
  static bool ApplyMaterialDescription(
    vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkMultiMaterialProperty* materials);

  /// The node's segmentation on the grid of its volume's image data (same
  /// extent; origin, spacing and direction as that image: the IJK frame
  /// Slicer renders volumes in): label n + 1 where segment n of
  /// `segmentIds` is (the segmentation's order; later segments win where
  /// segments overlap), 0 elsewhere. Returns false, with `labelMap` emptied,
  /// when there is no segmentation, no segment or no volume.
  static bool ExportSegmentLabelMap(
    vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkImageData* labelMap, vtkStringArray* segmentIds);

  /// The segments of `segmentIds` as label materials of `mapper` (label
  /// n + 1 for segment n) by the mapper's one label rule
  /// (vtkMultiMaterialVolumeMapper::SetLabelMaterial): a visible segment
  /// (visible, and visible in 3D, in the segmentation's display node) its
  /// colour and 3D opacity; a hidden one none, so that the volume
  /// property's own functions show there. Unchanged segments change
  /// nothing in the mapper. Returns the number of visible segments.
  static int ApplySegmentLooks(vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkStringArray* segmentIds,
    vtkMultiMaterialVolumeMapper* mapper);

  /// The node's segment material parameters on the mapper, by label.
  static void ApplySegmentMaterialParameters(vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node,
    vtkStringArray* segmentIds, vtkMultiMaterialVolumeMapper* mapper);

protected:
  vtkSlicerMultiMaterialVolumeRenderingLogic();
  ~vtkSlicerMultiMaterialVolumeRenderingLogic() override;
  vtkSlicerMultiMaterialVolumeRenderingLogic(const vtkSlicerMultiMaterialVolumeRenderingLogic&) = delete;
  void operator=(const vtkSlicerMultiMaterialVolumeRenderingLogic&) = delete;

  /// Registers the display node class; with an application logic that
  /// knows the Volume Rendering logic, also the rendering method.
  void RegisterNodes() override;

private:
  vtkWeakPointer<vtkSlicerVolumeRenderingLogic> VolumeRenderingLogic;
};

#endif
