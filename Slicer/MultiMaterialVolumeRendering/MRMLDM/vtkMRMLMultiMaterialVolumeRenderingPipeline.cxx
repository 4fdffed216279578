#include "vtkMRMLMultiMaterialVolumeRenderingPipeline.h"

#include "vtkMRMLMultiMaterialVolumeRenderingDisplayNode.h"
#include "vtkSlicerMultiMaterialVolumeRenderingLogic.h"

// SlicerLayerDM
#include <vtkMRMLLayerDMPipelineFactory.h>

// Slicer
#include <vtkMRMLMarkupsNode.h>
#include <vtkMRMLMarkupsROINode.h>
#include <vtkMRMLSegmentationDisplayNode.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTransformNode.h>
#include <vtkMRMLTransformableNode.h>
#include <vtkMRMLViewNode.h>
#include <vtkMRMLVolumeNode.h>
#include <vtkMRMLVolumePropertyNode.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>

// MM-RTM
#include <vtkMultiMaterialProperty.h>
#include <vtkMultiMaterialVolumeMapper.h>

// VTK
#include <vtkCallbackCommand.h>
#include <vtkColorTransferFunction.h>
#include <vtkCommand.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPlane.h>
#include <vtkPlanes.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWeakPointer.h>

#include <algorithm>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkMRMLMultiMaterialVolumeRenderingPipeline);

namespace
{
// What the label map is made of, by the pointers and modification times VTK
// keeps: the segments (their order and binary labelmaps), the volume's
// image and node, and both nodes' parent transforms. The label map is
// exported again when they differ from the last export's.
struct LabelMapInputs
{
  std::vector<std::string> Segments;
  std::vector<std::pair<vtkDataObject*, vtkMTimeType>> Labelmaps;
  vtkImageData* Image = nullptr;
  vtkMTimeType ImageTime = 0, VolumeNodeTime = 0;
  std::vector<std::pair<vtkMRMLTransformNode*, vtkMTimeType>> Transforms;

  bool operator==(const LabelMapInputs& o) const
  {
    return std::tie(Segments, Labelmaps, Image, ImageTime, VolumeNodeTime, Transforms) ==
      std::tie(o.Segments, o.Labelmaps, o.Image, o.ImageTime, o.VolumeNodeTime, o.Transforms);
  }
};

LabelMapInputs ReadLabelMapInputs(vtkMRMLSegmentationNode* segmentation, vtkMRMLVolumeNode* volume)
{
  LabelMapInputs now;
  vtkSegmentation* segments = segmentation->GetSegmentation();
  segments->GetSegmentIDs(now.Segments);
  const char* labelmap = vtkSegmentationConverter::GetBinaryLabelmapRepresentationName();
  for (const std::string& id : now.Segments)
  {
    vtkSegment* segment = segments->GetSegment(id);
    vtkDataObject* data = segment ? segment->GetRepresentation(labelmap) : nullptr;
    now.Labelmaps.emplace_back(data, data ? data->GetMTime() : 0);
  }
  now.Image = volume->GetImageData();
  now.ImageTime = now.Image ? now.Image->GetMTime() : 0;
  now.VolumeNodeTime = volume->GetMTime();
  for (vtkMRMLTransformableNode* node :
    { static_cast<vtkMRMLTransformableNode*>(volume), static_cast<vtkMRMLTransformableNode*>(segmentation) })
  {
    vtkMRMLTransformNode* parent = node->GetParentTransformNode();
    now.Transforms.emplace_back(parent, parent ? parent->GetTransformToWorldMTime() : 0);
  }
  return now;
}
}

struct vtkMRMLMultiMaterialVolumeRenderingPipeline::Internals
{
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkMultiMaterialVolumeMapper> Mapper;
  vtkNew<vtkMultiMaterialProperty> Materials;

  // The nodes this pipeline observes besides its display node.
  vtkWeakPointer<vtkMRMLNode> VolumeNode, PropertyNode, ROINode, SegmentationNode, SegmentationDisplayNode;

  // With a segmentation: the label map on the volume's grid, the segment
  // of each label, and what the label map was last exported from.
  vtkNew<vtkImageData> LabelMap;
  vtkNew<vtkStringArray> SegmentIds;
  LabelMapInputs LabelMapExported;
  std::string MaterialDescription = "\n"; // preset and JSON last applied ("\n": none yet)

  vtkNew<vtkMatrix4x4> Matrix;

  vtkWeakPointer<vtkRenderer> Renderer;
  vtkNew<vtkCallbackCommand> RenderEnd;
};

vtkMRMLMultiMaterialVolumeRenderingPipeline::vtkMRMLMultiMaterialVolumeRenderingPipeline()
  : Internal(new Internals)
{
  Internals& in = *this->Internal;
  in.Volume->SetMapper(in.Mapper);
  in.Volume->VisibilityOff();
  in.Volume->PickableOff();
  in.RenderEnd->SetClientData(this);
  in.RenderEnd->SetCallback([](vtkObject*, unsigned long, void* self, void*)
    { static_cast<vtkMRMLMultiMaterialVolumeRenderingPipeline*>(self)->OnRenderEnd(); });
}

vtkMRMLMultiMaterialVolumeRenderingPipeline::~vtkMRMLMultiMaterialVolumeRenderingPipeline()
{
  if (this->Internal->Renderer)
    this->OnRendererRemoved(this->Internal->Renderer);
}

bool vtkMRMLMultiMaterialVolumeRenderingPipeline::RegisterPipelineCreator()
{
  static bool registered = false;
  if (registered)
    return false;
  registered = true;
  vtkMRMLLayerDMPipelineFactory::GetInstance()->AddPipelineCreator(
    [](vtkMRMLAbstractViewNode* viewNode, vtkMRMLNode* node) -> vtkSmartPointer<vtkMRMLLayerDMPipeline>
    {
      if (!vtkMRMLViewNode::SafeDownCast(viewNode) ||
        !vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(node))
        return nullptr;
      auto pipeline = vtkSmartPointer<vtkMRMLMultiMaterialVolumeRenderingPipeline>::New();
      pipeline->SetViewNode(viewNode);
      pipeline->SetDisplayNode(node);
      return pipeline;
    });
  return true;
}

vtkMultiMaterialVolumeMapper* vtkMRMLMultiMaterialVolumeRenderingPipeline::GetMapper()
{
  return this->Internal->Mapper;
}

vtkVolume* vtkMRMLMultiMaterialVolumeRenderingPipeline::GetVolume()
{
  return this->Internal->Volume;
}

void vtkMRMLMultiMaterialVolumeRenderingPipeline::SetDisplayNode(vtkMRMLNode* displayNode)
{
  this->Superclass::SetDisplayNode(displayNode);
  this->UpdateObservedNodes();
}

void vtkMRMLMultiMaterialVolumeRenderingPipeline::OnRendererAdded(vtkRenderer* renderer)
{
  Internals& in = *this->Internal;
  if (!renderer)
    return;
  renderer->AddVolume(in.Volume);
  renderer->AddObserver(vtkCommand::EndEvent, in.RenderEnd);
  in.Renderer = renderer;
}

void vtkMRMLMultiMaterialVolumeRenderingPipeline::OnRendererRemoved(vtkRenderer* renderer)
{
  Internals& in = *this->Internal;
  if (!renderer)
    return;
  renderer->RemoveObserver(in.RenderEnd);
  renderer->RemoveVolume(in.Volume);
  // The texture the image is drawn with belongs to this window's context.
  if (vtkRenderWindow* window = renderer->GetRenderWindow())
    in.Volume->ReleaseGraphicsResources(window);
  if (in.Renderer == renderer)
    in.Renderer = nullptr;
}

// While the image is not converged, each render asks for another one: the
// view refines while it is idle (Slicer's views compress the requests).
void vtkMRMLMultiMaterialVolumeRenderingPipeline::OnRenderEnd()
{
  Internals& in = *this->Internal;
  if (in.Volume->GetVisibility() && in.Mapper->GetAccumulatedSamples() > 0 && !in.Mapper->IsConverged())
    this->RequestRender();
}

void vtkMRMLMultiMaterialVolumeRenderingPipeline::OnUpdate(vtkObject* object, unsigned long eventId, void* callData)
{
  this->Superclass::OnUpdate(object, eventId, callData);
  this->UpdateDisplay();
}

// Observes what the display node refers to; the references may change at
// any update.
void vtkMRMLMultiMaterialVolumeRenderingPipeline::UpdateObservedNodes()
{
  Internals& in = *this->Internal;
  auto* node = vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(this->GetDisplayNode());
  vtkMRMLNode* volume = node ? node->GetVolumeNode() : nullptr;
  vtkMRMLNode* property = node ? node->GetVolumePropertyNode() : nullptr;
  vtkMRMLNode* roi = node ? node->GetROINode() : nullptr;
  vtkMRMLSegmentationNode* segmentation = node ? node->GetSegmentationNode() : nullptr;
  vtkMRMLNode* segmentationDisplay = segmentation ? segmentation->GetDisplayNode() : nullptr;

  const std::vector<unsigned long> volumeEvents{ vtkCommand::ModifiedEvent, vtkMRMLVolumeNode::ImageDataModifiedEvent,
    vtkMRMLTransformableNode::TransformModifiedEvent };
  const std::vector<unsigned long> roiEvents{ vtkCommand::ModifiedEvent, vtkMRMLMarkupsNode::PointModifiedEvent,
    vtkMRMLTransformableNode::TransformModifiedEvent };
  const std::vector<unsigned long> segmentationEvents{ vtkCommand::ModifiedEvent,
    vtkMRMLTransformableNode::TransformModifiedEvent, vtkSegmentation::SegmentAdded, vtkSegmentation::SegmentRemoved,
    vtkSegmentation::SegmentModified, vtkSegmentation::SourceRepresentationModified };
  this->UpdateObservation(in.VolumeNode, volume, volumeEvents);
  this->UpdateObservation(in.PropertyNode, property, vtkCommand::ModifiedEvent);
  this->UpdateObservation(in.ROINode, roi, roiEvents);
  this->UpdateObservation(in.SegmentationNode, segmentation, segmentationEvents);
  this->UpdateObservation(in.SegmentationDisplayNode, segmentationDisplay, vtkCommand::ModifiedEvent);
  in.VolumeNode = volume;
  in.PropertyNode = property;
  in.ROINode = roi;
  in.SegmentationNode = segmentation;
  in.SegmentationDisplayNode = segmentationDisplay;
}

void vtkMRMLMultiMaterialVolumeRenderingPipeline::UpdateFromMRML()
{
  Internals& in = *this->Internal;
  this->UpdateObservedNodes();
  auto* node = vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(this->GetDisplayNode());
  vtkMRMLAbstractViewNode* view = this->GetViewNode();
  vtkMRMLVolumeNode* volumeNode = node ? node->GetVolumeNode() : nullptr;
  vtkMRMLVolumePropertyNode* propertyNode = node ? node->GetVolumePropertyNode() : nullptr;
  const bool visible = node && view && volumeNode && volumeNode->GetImageData() && propertyNode &&
    propertyNode->GetVolumeProperty() && node->GetVisibility(view->GetID()) && node->GetVisibility3D();
  if (!visible)
  {
    in.Volume->VisibilityOff();
    return;
  }
  if (in.Mapper->GetInput() != volumeNode->GetImageData())
    in.Mapper->SetInputData(volumeNode->GetImageData());
  vtkSlicerMultiMaterialVolumeRenderingLogic::ApplyRenderSettings(node, in.Mapper);
  this->UpdateGeometry();
  this->UpdateProperty();
  this->UpdateCropping();
  in.Volume->VisibilityOn();
}

// IJK to world: the volume's IJK-to-RAS matrix under its parent transforms.
void vtkMRMLMultiMaterialVolumeRenderingPipeline::UpdateGeometry()
{
  Internals& in = *this->Internal;
  auto* node = vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(this->GetDisplayNode());
  vtkMRMLVolumeNode* volumeNode = node->GetVolumeNode();
  vtkNew<vtkMatrix4x4> ijkToRas;
  volumeNode->GetIJKToRASMatrix(ijkToRas);
  vtkNew<vtkMatrix4x4> toWorld;
  if (vtkMRMLTransformNode* parent = volumeNode->GetParentTransformNode())
  {
    if (!parent->IsTransformToWorldLinear())
      vtkWarningMacro("volume " << volumeNode->GetName() << " is under a non-linear transform; only its linear part "
                                << "is rendered");
    parent->GetMatrixTransformToWorld(toWorld);
  }
  // The mapper compares the matrix by value: the same one again restarts nothing.
  vtkNew<vtkMatrix4x4> matrix;
  vtkMatrix4x4::Multiply4x4(toWorld, ijkToRas, matrix);
  in.Matrix->DeepCopy(matrix);
  in.Volume->SetUserMatrix(in.Matrix);
  in.Volume->Modified();
}

// The volume property node's property, as it is (rendering never changes
// it); with a segmentation, its segments as the mapper's label materials;
// then the material preset and the segments' material parameters.
void vtkMRMLMultiMaterialVolumeRenderingPipeline::UpdateProperty()
{
  Internals& in = *this->Internal;
  auto* node = vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(this->GetDisplayNode());
  vtkVolumeProperty* property = node->GetVolumePropertyNode()->GetVolumeProperty();
  vtkMRMLSegmentationNode* segmentation = node->GetSegmentationNode();
  bool labels = false;
  if (segmentation && segmentation->GetSegmentation())
  {
    LabelMapInputs inputs = ReadLabelMapInputs(segmentation, node->GetVolumeNode());
    if (!(inputs == in.LabelMapExported))
    {
      vtkSlicerMultiMaterialVolumeRenderingLogic::ExportSegmentLabelMap(node, in.LabelMap, in.SegmentIds);
      in.LabelMap->Modified();
      in.LabelMapExported = std::move(inputs);
      in.Mapper->RemoveAllLabelMaterials(); // the labels are numbered anew
    }
    labels = in.SegmentIds->GetNumberOfValues() > 0;
  }
  if (in.Volume->GetProperty() != property)
    in.Volume->SetProperty(property);
  if (labels)
  {
    vtkSlicerMultiMaterialVolumeRenderingLogic::ApplySegmentLooks(node, in.SegmentIds, in.Mapper);
    if (in.Mapper->GetMaskInput() != in.LabelMap.GetPointer())
      in.Mapper->SetMaskInput(in.LabelMap);
    in.Mapper->SetMaskTypeToLabelMap();
    vtkSlicerMultiMaterialVolumeRenderingLogic::ApplySegmentMaterialParameters(node, in.SegmentIds, in.Mapper);
  }
  else
  {
    if (in.Mapper->GetMaskInput())
      in.Mapper->SetMaskInput(nullptr);
    in.Mapper->RemoveAllLabelMaterials();
  }

  const std::string description = std::string(node->GetMaterialPreset()) + '\n' + node->GetSceneJSON();
  if (description != in.MaterialDescription)
  {
    const bool useMaterials = vtkSlicerMultiMaterialVolumeRenderingLogic::ApplyMaterialDescription(node, in.Materials);
    in.Mapper->SetMultiMaterialProperty(useMaterials ? in.Materials.GetPointer() : nullptr);
    in.MaterialDescription = description;
  }
}

// Cropping by the ROI: its six faces, normals inward, as clipping planes in
// world space (the mapper compares them by value: the same planes again
// restart nothing).
void vtkMRMLMultiMaterialVolumeRenderingPipeline::UpdateCropping()
{
  Internals& in = *this->Internal;
  auto* node = vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(this->GetDisplayNode());
  in.Mapper->RemoveAllClippingPlanes();
  vtkNew<vtkPlanes> planes;
  if (auto* roi = vtkMRMLMarkupsROINode::SafeDownCast(node->GetROINode()); roi && node->GetCroppingEnabled())
  {
    roi->GetPlanesWorld(planes, !roi->GetInsideOut());
    for (int i = 0; i < planes->GetNumberOfPlanes(); ++i)
    {
      vtkNew<vtkPlane> plane; // a copy: vtkPlanes hands out one plane object, reused
      plane->SetOrigin(planes->GetPlane(i)->GetOrigin());
      plane->SetNormal(planes->GetPlane(i)->GetNormal());
      in.Mapper->AddClippingPlane(plane);
    }
  }
}

void vtkMRMLMultiMaterialVolumeRenderingPipeline::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Segments: " << this->Internal->SegmentIds->GetNumberOfValues() << "\n";
  os << indent << "AccumulatedSamples: " << this->Internal->Mapper->GetAccumulatedSamples() << "\n";
}
