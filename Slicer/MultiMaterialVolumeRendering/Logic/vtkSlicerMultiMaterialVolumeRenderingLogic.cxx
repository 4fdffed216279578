#include "vtkSlicerMultiMaterialVolumeRenderingLogic.h"

#include "vtkMRMLMultiMaterialVolumeRenderingDisplayNode.h"

// Slicer
#include <vtkMRMLApplicationLogic.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationDisplayNode.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTransformNode.h>
#include <vtkMRMLVolumeNode.h>
#include <vtkOrientedImageData.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>
#include <vtkSlicerVolumeRenderingLogic.h>

// MM-RTM
#include <vtkMultiMaterialProperty.h>
#include <vtkMultiMaterialVolumeMapper.h>

// VTK
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkStringArray.h>
#include <vtkVolumeProperty.h>

#include <algorithm>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkSlicerMultiMaterialVolumeRenderingLogic);

vtkSlicerMultiMaterialVolumeRenderingLogic::vtkSlicerMultiMaterialVolumeRenderingLogic() = default;

vtkSlicerMultiMaterialVolumeRenderingLogic::~vtkSlicerMultiMaterialVolumeRenderingLogic() = default;

void vtkSlicerMultiMaterialVolumeRenderingLogic::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "VolumeRenderingLogic: " << this->VolumeRenderingLogic.GetPointer() << "\n";
}

void vtkSlicerMultiMaterialVolumeRenderingLogic::RegisterNodes()
{
  vtkMRMLScene* scene = this->GetMRMLScene();
  if (!scene)
    return;
  if (!scene->IsNodeClassRegistered("vtkMRMLMultiMaterialVolumeRenderingDisplayNode"))
    scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLMultiMaterialVolumeRenderingDisplayNode>::New());
  if (!this->VolumeRenderingLogic && this->GetMRMLApplicationLogic())
  {
    this->SetVolumeRenderingLogic(
      vtkSlicerVolumeRenderingLogic::SafeDownCast(this->GetMRMLApplicationLogic()->GetModuleLogic("VolumeRendering")));
  }
}

void vtkSlicerMultiMaterialVolumeRenderingLogic::SetVolumeRenderingLogic(vtkSlicerVolumeRenderingLogic* logic)
{
  if (logic == this->VolumeRenderingLogic)
    return;
  this->VolumeRenderingLogic = logic;
  if (logic)
  {
    // The node class must be known to the scene the Volume Rendering logic
    // creates display nodes in.
    if (vtkMRMLScene* scene = logic->GetMRMLScene())
    {
      if (!scene->IsNodeClassRegistered("vtkMRMLMultiMaterialVolumeRenderingDisplayNode"))
        scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLMultiMaterialVolumeRenderingDisplayNode>::New());
    }
    logic->RegisterRenderingMethod(GetRenderingMethodName(), "vtkMRMLMultiMaterialVolumeRenderingDisplayNode");
  }
  this->Modified();
}

vtkSlicerVolumeRenderingLogic* vtkSlicerMultiMaterialVolumeRenderingLogic::GetVolumeRenderingLogic()
{
  return this->VolumeRenderingLogic;
}

bool vtkSlicerMultiMaterialVolumeRenderingLogic::IsRenderingMethodRegistered()
{
  if (!this->VolumeRenderingLogic)
    return false;
  const auto methods = this->VolumeRenderingLogic->GetRenderingMethods();
  const auto found = methods.find(GetRenderingMethodName());
  return found != methods.end() && found->second == "vtkMRMLMultiMaterialVolumeRenderingDisplayNode";
}

void vtkSlicerMultiMaterialVolumeRenderingLogic::ApplyRenderSettings(
  vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkMultiMaterialVolumeMapper* mapper)
{
  if (!node || !mapper)
    return;
  mapper->SetSamplesPerRender(node->GetSamplesPerRender());
  mapper->SetMaximumSamples(node->GetMaximumSamples());
  mapper->SetNoiseTarget(node->GetNoiseTarget());
  mapper->SetAsynchronousRefinement(node->GetAsynchronousRefinement());
  mapper->SetMaximumBounces(node->GetMaximumBounces());
  mapper->SetShadowExtinctionScale(node->GetShadowExtinctionScale());
  mapper->SetSeed(node->GetSeed());
  switch (node->GetAccelerator())
  {
    case vtkMRMLMultiMaterialVolumeRenderingDisplayNode::Macrocell:
      mapper->SetAccelerator(vtkMultiMaterialVolumeMapper::MACROCELL);
      break;
    case vtkMRMLMultiMaterialVolumeRenderingDisplayNode::NoAccelerator:
      mapper->SetAccelerator(vtkMultiMaterialVolumeMapper::NO_ACCELERATOR);
      break;
    default:
      mapper->SetAccelerator(vtkMultiMaterialVolumeMapper::OCTREE);
  }
  switch (node->GetDenoisingMode())
  {
    case vtkMRMLMultiMaterialVolumeRenderingDisplayNode::DenoisingOff:
      mapper->SetDenoisingModeToOff();
      break;
    case vtkMRMLMultiMaterialVolumeRenderingDisplayNode::DenoisingAlways:
      mapper->SetDenoisingModeToAlways();
      break;
    default:
      mapper->SetDenoisingModeToAuto();
  }
  switch (node->GetBackend())
  {
    case vtkMRMLMultiMaterialVolumeRenderingDisplayNode::CPU:
      mapper->SetBackend(vtkMultiMaterialVolumeMapper::CPU);
      break;
    case vtkMRMLMultiMaterialVolumeRenderingDisplayNode::CUDA:
      mapper->SetBackend(vtkMultiMaterialVolumeMapper::CUDA);
      break;
    default:
      mapper->SetBackend(vtkMultiMaterialVolumeMapper::AUTO);
  }
}

bool vtkSlicerMultiMaterialVolumeRenderingLogic::ApplyMaterialDescription(
  vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkMultiMaterialProperty* materials)
{
  if (!node || !materials)
    return false;
  const std::string preset = node->GetMaterialPreset();
  const std::string json = node->GetSceneJSON();
  if (preset.empty() && json.empty())
    return false;
  // Each call replaces the description, so that a preset and JSON removed
  // from the node are removed from the render too.
  if (preset.empty())
    materials->SetSceneJSON(json.c_str());
  else if (materials->SetPreset(preset.c_str()) && !json.empty())
    materials->MergeSceneJSON(json.c_str());
  return true;
}

bool vtkSlicerMultiMaterialVolumeRenderingLogic::ExportSegmentLabelMap(
  vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkImageData* labelMap, vtkStringArray* segmentIds)
{
  if (!labelMap || !segmentIds)
    return false;
  labelMap->Initialize();
  segmentIds->Reset();
  vtkMRMLSegmentationNode* segmentationNode = node ? node->GetSegmentationNode() : nullptr;
  vtkMRMLVolumeNode* volume = node ? node->GetVolumeNode() : nullptr;
  vtkImageData* image = volume ? volume->GetImageData() : nullptr;
  if (!segmentationNode || !segmentationNode->GetSegmentation() || !image)
    return false;
  vtkSegmentation* segmentation = segmentationNode->GetSegmentation();
  std::vector<std::string> ids;
  segmentation->GetSegmentIDs(ids);
  if (ids.empty())
    return false;
  const char* labelmapName = vtkSegmentationConverter::GetBinaryLabelmapRepresentationName();
  if (!segmentation->ContainsRepresentation(labelmapName) && !segmentationNode->CreateBinaryLabelmapRepresentation())
  {
    vtkErrorWithObjectMacro(node,
      "segmentation " << segmentationNode->GetName() << " has no binary labelmap representation and none can be made");
    return false;
  }

  // The volume's grid (IJK to RAS), in the segmentation's coordinate frame:
  // the two may sit under different (linear) transforms.
  vtkNew<vtkMatrix4x4> ijkToRas;
  volume->GetIJKToRASMatrix(ijkToRas);
  vtkNew<vtkMatrix4x4> volumeToSegmentation;
  if (!vtkMRMLTransformNode::GetMatrixTransformBetweenNodes(
        volume->GetParentTransformNode(), segmentationNode->GetParentTransformNode(), volumeToSegmentation))
  {
    vtkErrorWithObjectMacro(node,
      "the transform between volume " << volume->GetName() << " and segmentation " << segmentationNode->GetName()
                                      << " is not linear: the segments are not rendered");
    return false;
  }
  vtkNew<vtkMatrix4x4> gridToSegmentation;
  vtkMatrix4x4::Multiply4x4(volumeToSegmentation, ijkToRas, gridToSegmentation);
  vtkNew<vtkOrientedImageData> geometry;
  geometry->SetExtent(image->GetExtent());
  geometry->SetImageToWorldMatrix(gridToSegmentation);

  vtkNew<vtkIntArray> labels;
  for (size_t i = 0; i < ids.size(); ++i)
    labels->InsertNextValue(static_cast<int>(i) + 1);
  vtkNew<vtkOrientedImageData> merged;
  if (!segmentationNode->GenerateMergedLabelmap(
        merged, vtkSegmentation::EXTENT_REFERENCE_GEOMETRY, geometry, ids, labels))
  {
    vtkErrorWithObjectMacro(node,
      "the segments of " << segmentationNode->GetName() << " could not be merged onto the grid of "
                         << volume->GetName());
    return false;
  }
  // The label map on the image's own frame: the renderer places both with
  // the volume's IJK-to-RAS matrix.
  labelMap->SetExtent(image->GetExtent());
  labelMap->SetOrigin(image->GetOrigin());
  labelMap->SetSpacing(image->GetSpacing());
  labelMap->SetDirectionMatrix(image->GetDirectionMatrix());
  labelMap->GetPointData()->SetScalars(merged->GetPointData()->GetScalars());
  for (const std::string& id : ids)
    segmentIds->InsertNextValue(id);
  return true;
}

int vtkSlicerMultiMaterialVolumeRenderingLogic::ApplySegmentLooks(vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node,
  vtkStringArray* segmentIds, vtkMultiMaterialVolumeMapper* mapper)
{
  vtkMRMLSegmentationNode* segmentationNode = node ? node->GetSegmentationNode() : nullptr;
  if (!segmentationNode || !segmentIds || !mapper)
    return 0;
  auto* display = vtkMRMLSegmentationDisplayNode::SafeDownCast(segmentationNode->GetDisplayNode());
  vtkSegmentation* segmentation = segmentationNode->GetSegmentation();
  int visible = 0;
  for (vtkIdType i = 0; i < segmentIds->GetNumberOfValues(); ++i)
  {
    const std::string id = segmentIds->GetValue(i);
    const int label = static_cast<int>(i) + 1;
    vtkSegment* segment = segmentation->GetSegment(id);
    const bool shown =
      segment && (!display || (display->GetSegmentVisibility(id) && display->GetSegmentVisibility3D(id)));
    if (!shown)
    {
      mapper->RemoveLabelMaterial(label);
      continue;
    }
    double rgb[3];
    segment->GetColor(rgb);
    if (display)
      display->GetSegmentColor(id, rgb); // with the display node's override, if any
    const double opacity3D = display ? display->GetSegmentOpacity3D(id) : 1.0;
    mapper->SetLabelMaterial(label, rgb[0], rgb[1], rgb[2], std::clamp(opacity3D, 0.0, 1.0));
    ++visible;
  }
  return visible;
}

void vtkSlicerMultiMaterialVolumeRenderingLogic::ApplySegmentMaterialParameters(
  vtkMRMLMultiMaterialVolumeRenderingDisplayNode* node, vtkStringArray* segmentIds,
  vtkMultiMaterialVolumeMapper* mapper)
{
  if (!node || !segmentIds || !mapper)
    return;
  // Unchanged parameters change nothing in the mapper.
  for (vtkIdType i = 0; i < segmentIds->GetNumberOfValues(); ++i)
    mapper->SetLabelMaterialParameters(
      static_cast<int>(i) + 1, node->GetSegmentMaterialParameters(segmentIds->GetValue(i).c_str()));
}
