#include "vtkMRMLMultiMaterialVolumeRenderingDisplayNode.h"

#include <vtkMRMLDisplayableNode.h>
#include <vtkMRMLNodePropertyMacros.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkSegmentation.h>

#include <vtkCommand.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkStringArray.h>
#include <vtkVersionMacros.h>

#include <cctype>
#include <cstring>
#include <string>
#include <sstream>

vtkMRMLNodeNewMacro(vtkMRMLMultiMaterialVolumeRenderingDisplayNode);

namespace
{
// Creates the display node by its class name for vtkObjectFactory::CreateInstance.
class NodeFactory : public vtkObjectFactory
{
public:
  static NodeFactory* New()
  {
    auto* factory = new NodeFactory;
    factory->InitializeObjectBase();
    return factory;
  }
  vtkTypeMacro(NodeFactory, vtkObjectFactory);
  const char* GetVTKSourceVersion() override { return VTK_SOURCE_VERSION; }
  const char* GetDescription() override { return "MM-RTM volume rendering display node"; }

protected:
  NodeFactory()
  {
    this->RegisterOverride("vtkMRMLMultiMaterialVolumeRenderingDisplayNode",
      "vtkMRMLMultiMaterialVolumeRenderingDisplayNode", "the MM-RTM display node by class name", 1,
      []() -> vtkObject* { return vtkMRMLMultiMaterialVolumeRenderingDisplayNode::New(); });
  }
};
} // namespace

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::RegisterNodeFactory()
{
  static const bool registered = []
  {
    vtkNew<NodeFactory> factory;
    vtkObjectFactory::RegisterFactory(factory);
    return true;
  }();
  (void)registered;
}

namespace
{
const char* const AcceleratorNames[] = { "octree", "macrocell", "none" };
const char* const BackendNames[] = { "auto", "cpu", "cuda" };
const char* const DenoisingModeNames[] = { "off", "auto", "always" };

// Percent-encoding of everything but letters, digits, '_', '.' and '-':
// safe inside an XML attribute and for the separators below.
std::string PercentEncode(const std::string& text)
{
  static const char* const hex = "0123456789ABCDEF";
  std::string out;
  for (const unsigned char c : text)
  {
    if (std::isalnum(c) || c == '_' || c == '.' || c == '-')
      out += static_cast<char>(c);
    else
    {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

std::string PercentDecode(const std::string& text)
{
  std::string out;
  for (size_t i = 0; i < text.size(); ++i)
  {
    if (text[i] == '%' && i + 2 < text.size() && std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
      std::isxdigit(static_cast<unsigned char>(text[i + 2])))
    {
      out += static_cast<char>(std::stoi(text.substr(i + 1, 2), nullptr, 16));
      i += 2;
    }
    else
      out += text[i];
  }
  return out;
}

// Segment material parameters as one XML attribute: "id=json" entries,
// both percent-encoded, joined by ';'.
std::string EncodeParameters(const std::map<std::string, std::string>& parameters)
{
  std::string out;
  for (const auto& [id, json] : parameters)
  {
    if (!out.empty())
      out += ';';
    out += PercentEncode(id) + '=' + PercentEncode(json);
  }
  return out;
}

std::map<std::string, std::string> DecodeParameters(const std::string& text)
{
  std::map<std::string, std::string> parameters;
  std::stringstream entries(text);
  std::string entry;
  while (std::getline(entries, entry, ';'))
  {
    const auto eq = entry.find('=');
    if (eq != std::string::npos)
      parameters[PercentDecode(entry.substr(0, eq))] = PercentDecode(entry.substr(eq + 1));
  }
  return parameters;
}
}

vtkMRMLMultiMaterialVolumeRenderingDisplayNode::vtkMRMLMultiMaterialVolumeRenderingDisplayNode()
{
  // The segmentation's content and display (segment colours, visibility,
  // 3D opacity) change what this node renders.
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkCommand::ModifiedEvent);
  events->InsertNextValue(vtkMRMLDisplayableNode::DisplayModifiedEvent);
  events->InsertNextValue(vtkSegmentation::SegmentAdded);
  events->InsertNextValue(vtkSegmentation::SegmentRemoved);
  events->InsertNextValue(vtkSegmentation::SegmentModified);
  events->InsertNextValue(vtkSegmentation::SourceRepresentationModified);
  events->InsertNextValue(vtkSegmentation::SegmentsOrderModified);
  this->AddNodeReferenceRole(GetSegmentationNodeReferenceRole(), "segmentationNodeRef", events);
}

vtkMRMLMultiMaterialVolumeRenderingDisplayNode::~vtkMRMLMultiMaterialVolumeRenderingDisplayNode() = default;

const char* vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetAcceleratorAsString(int id)
{
  return id >= 0 && id < Accelerator_Last ? AcceleratorNames[id] : "";
}

int vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetAcceleratorFromString(const char* name)
{
  for (int i = 0; name && i < Accelerator_Last; ++i)
  {
    if (std::strcmp(name, AcceleratorNames[i]) == 0)
      return i;
  }
  return -1;
}

const char* vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetDenoisingModeAsString(int id)
{
  return id >= 0 && id < DenoisingMode_Last ? DenoisingModeNames[id] : "";
}

int vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetDenoisingModeFromString(const char* name)
{
  for (int i = 0; name && i < DenoisingMode_Last; ++i)
  {
    if (std::strcmp(name, DenoisingModeNames[i]) == 0)
      return i;
  }
  return -1;
}

const char* vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetBackendAsString(int id)
{
  return id >= 0 && id < Backend_Last ? BackendNames[id] : "";
}

int vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetBackendFromString(const char* name)
{
  for (int i = 0; name && i < Backend_Last; ++i)
  {
    if (std::strcmp(name, BackendNames[i]) == 0)
      return i;
  }
  return -1;
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SetAndObserveSegmentationNodeID(const char* segmentationNodeId)
{
  this->SetAndObserveNodeReferenceID(GetSegmentationNodeReferenceRole(), segmentationNodeId);
}

const char* vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetSegmentationNodeID()
{
  return this->GetNodeReferenceID(GetSegmentationNodeReferenceRole());
}

vtkMRMLSegmentationNode* vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetSegmentationNode()
{
  return vtkMRMLSegmentationNode::SafeDownCast(this->GetNodeReference(GetSegmentationNodeReferenceRole()));
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SetSegmentMaterialParameters(
  const char* segmentId, const char* json)
{
  if (!segmentId)
    return;
  const auto found = this->SegmentMaterialParameters.find(segmentId);
  if (!json || !*json)
  {
    if (found == this->SegmentMaterialParameters.end())
      return;
    this->SegmentMaterialParameters.erase(found);
  }
  else
  {
    if (found != this->SegmentMaterialParameters.end() && found->second == json)
      return;
    this->SegmentMaterialParameters[segmentId] = json;
  }
  this->Modified();
}

const char* vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetSegmentMaterialParameters(const char* segmentId)
{
  const auto found =
    segmentId ? this->SegmentMaterialParameters.find(segmentId) : this->SegmentMaterialParameters.end();
  return found == this->SegmentMaterialParameters.end() ? nullptr : found->second.c_str();
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::GetSegmentIDsWithMaterialParameters(vtkStringArray* segmentIds)
{
  if (!segmentIds)
    return;
  segmentIds->Reset();
  for (const auto& entry : this->SegmentMaterialParameters)
    segmentIds->InsertNextValue(entry.first);
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::RemoveAllSegmentMaterialParameters()
{
  if (this->SegmentMaterialParameters.empty())
    return;
  this->SegmentMaterialParameters.clear();
  this->Modified();
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::ProcessMRMLEvents(
  vtkObject* caller, unsigned long event, void* callData)
{
  this->Superclass::ProcessMRMLEvents(caller, event, callData);
  if (caller && caller == this->GetSegmentationNode())
    this->Modified();
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::WriteXML(ostream& of, int nIndent)
{
  this->Superclass::WriteXML(of, nIndent);
  vtkMRMLWriteXMLBeginMacro(of);
  vtkMRMLWriteXMLIntMacro(samplesPerRender, SamplesPerRender);
  vtkMRMLWriteXMLIntMacro(maximumSamples, MaximumSamples);
  vtkMRMLWriteXMLFloatMacro(noiseTarget, NoiseTarget);
  vtkMRMLWriteXMLBooleanMacro(asynchronousRefinement, AsynchronousRefinement);
  vtkMRMLWriteXMLIntMacro(maximumBounces, MaximumBounces);
  vtkMRMLWriteXMLFloatMacro(shadowExtinctionScale, ShadowExtinctionScale);
  vtkMRMLWriteXMLEnumMacro(accelerator, Accelerator);
  vtkMRMLWriteXMLEnumMacro(backend, Backend);
  vtkMRMLWriteXMLEnumMacro(denoisingMode, DenoisingMode);
  vtkMRMLWriteXMLIntMacro(seed, Seed);
  vtkMRMLWriteXMLStringMacro(materialPreset, MaterialPreset);
  vtkMRMLWriteXMLStringMacro(sceneJSON, SceneJSON);
  vtkMRMLWriteXMLEndMacro();
  of << " segmentMaterialParameters=\"" << EncodeParameters(this->SegmentMaterialParameters) << "\"";
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::ReadXMLAttributes(const char** atts)
{
  const int wasModifying = this->StartModify();
  this->Superclass::ReadXMLAttributes(atts);
  vtkMRMLReadXMLBeginMacro(atts);
  vtkMRMLReadXMLIntMacro(samplesPerRender, SamplesPerRender);
  vtkMRMLReadXMLIntMacro(maximumSamples, MaximumSamples);
  vtkMRMLReadXMLFloatMacro(noiseTarget, NoiseTarget);
  vtkMRMLReadXMLBooleanMacro(asynchronousRefinement, AsynchronousRefinement);
  vtkMRMLReadXMLIntMacro(maximumBounces, MaximumBounces);
  vtkMRMLReadXMLFloatMacro(shadowExtinctionScale, ShadowExtinctionScale);
  vtkMRMLReadXMLEnumMacro(accelerator, Accelerator);
  vtkMRMLReadXMLEnumMacro(backend, Backend);
  vtkMRMLReadXMLEnumMacro(denoisingMode, DenoisingMode);
  vtkMRMLReadXMLIntMacro(seed, Seed);
  vtkMRMLReadXMLStringMacro(materialPreset, MaterialPreset);
  vtkMRMLReadXMLStringMacro(sceneJSON, SceneJSON);
  vtkMRMLReadXMLEndMacro();
  for (const char** a = atts; a && *a; a += 2)
  {
    if (std::strcmp(a[0], "segmentMaterialParameters") == 0)
      this->SegmentMaterialParameters = DecodeParameters(a[1]);
  }
  this->EndModify(wasModifying);
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::Copy(vtkMRMLNode* node)
{
  const int wasModifying = this->StartModify();
  this->Superclass::Copy(node);
  this->CopyContent(node, true);
  this->EndModify(wasModifying);
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::CopyContent(vtkMRMLNode* anode, bool deepCopy)
{
  const int wasModifying = this->StartModify();
  this->Superclass::CopyContent(anode, deepCopy);
  auto* node = vtkMRMLMultiMaterialVolumeRenderingDisplayNode::SafeDownCast(anode);
  if (node)
  {
    vtkMRMLCopyBeginMacro(anode);
    vtkMRMLCopyIntMacro(SamplesPerRender);
    vtkMRMLCopyIntMacro(MaximumSamples);
    vtkMRMLCopyFloatMacro(NoiseTarget);
    vtkMRMLCopyBooleanMacro(AsynchronousRefinement);
    vtkMRMLCopyIntMacro(MaximumBounces);
    vtkMRMLCopyFloatMacro(ShadowExtinctionScale);
    vtkMRMLCopyEnumMacro(Accelerator);
    vtkMRMLCopyEnumMacro(Backend);
    vtkMRMLCopyEnumMacro(DenoisingMode);
    vtkMRMLCopyIntMacro(Seed);
    vtkMRMLCopyStringMacro(MaterialPreset);
    vtkMRMLCopyStringMacro(SceneJSON);
    vtkMRMLCopyEndMacro();
    if (this->SegmentMaterialParameters != node->SegmentMaterialParameters)
    {
      this->SegmentMaterialParameters = node->SegmentMaterialParameters;
      this->Modified();
    }
  }
  this->EndModify(wasModifying);
}

void vtkMRMLMultiMaterialVolumeRenderingDisplayNode::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  vtkMRMLPrintBeginMacro(os, indent);
  vtkMRMLPrintIntMacro(SamplesPerRender);
  vtkMRMLPrintIntMacro(MaximumSamples);
  vtkMRMLPrintFloatMacro(NoiseTarget);
  vtkMRMLPrintBooleanMacro(AsynchronousRefinement);
  vtkMRMLPrintIntMacro(MaximumBounces);
  vtkMRMLPrintFloatMacro(ShadowExtinctionScale);
  vtkMRMLPrintEnumMacro(Accelerator);
  vtkMRMLPrintEnumMacro(Backend);
  vtkMRMLPrintEnumMacro(DenoisingMode);
  vtkMRMLPrintIntMacro(Seed);
  vtkMRMLPrintStringMacro(MaterialPreset);
  vtkMRMLPrintStringMacro(SceneJSON);
  vtkMRMLPrintEndMacro();
  os << indent << "SegmentMaterialParameters: " << EncodeParameters(this->SegmentMaterialParameters) << "\n";
}
