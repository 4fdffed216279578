#include "vtkMultiMaterialVolumeRepresentation.h"

#include "vtkCommand.h"
#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPVLODVolume.h"
#include "vtkPVRenderView.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "vtkSampleParallelVolumeMapper.h"

#include <algorithm>

vtkStandardNewMacro(vtkMultiMaterialVolumeRepresentation);

vtkMultiMaterialVolumeRepresentation::vtkMultiMaterialVolumeRepresentation()
{
  // The superclass made a vtkMultiBlockVolumeMapper; the path tracer takes
  // its place (the superclass's code only forwards the array selection and
  // the scalar mode to it).
  this->VolumeMapper = vtkSmartPointer<vtkSampleParallelVolumeMapper>::New();
  // Defaults for a first image without a GUI (pvbatch): one still render
  // gives 64 samples a pixel; a render of the unchanged view only redraws.
  this->SetSamplesPerRender(64);
  this->SetMaximumSamples(64);
  // A representation chosen for its path tracing: ParaView's volumes are
  // unshaded by default, and as VTK draws them (the mapper's VTK look) they
  // would glow unlit; here they scatter the lights, with shadows, under the
  // filmic curve.
  this->Mapper()->SetLookToFilmic();
}

vtkMultiMaterialVolumeRepresentation::~vtkMultiMaterialVolumeRepresentation()
{
  if (this->ObservedRenderer)
    this->ObservedRenderer->RemoveObserver(this->StartRenderObserver);
}

vtkSampleParallelVolumeMapper* vtkMultiMaterialVolumeRepresentation::Mapper()
{
  return static_cast<vtkSampleParallelVolumeMapper*>(this->VolumeMapper.Get());
}

void vtkMultiMaterialVolumeRepresentation::SetSamplesPerRender(int samples)
{
  this->Mapper()->SetTotalSamplesPerRender(samples);
}

void vtkMultiMaterialVolumeRepresentation::SetMaximumSamples(int samples)
{
  this->Mapper()->SetTotalMaximumSamples(samples);
}

void vtkMultiMaterialVolumeRepresentation::SetNoiseTarget(double target)
{
  this->Mapper()->SetTotalNoiseTarget(target);
}

void vtkMultiMaterialVolumeRepresentation::SetMaximumBounces(int bounces)
{
  this->Mapper()->SetMaximumBounces(bounces);
}

void vtkMultiMaterialVolumeRepresentation::SetShadowExtinctionScale(double scale)
{
  this->Mapper()->SetShadowExtinctionScale(scale);
}

void vtkMultiMaterialVolumeRepresentation::SetSeed(int seed)
{
  this->Mapper()->SetBaseSeed(seed);
}

void vtkMultiMaterialVolumeRepresentation::SetAccelerator(int accelerator)
{
  this->Mapper()->SetAccelerator(accelerator);
}

void vtkMultiMaterialVolumeRepresentation::SetSampler(int sampler)
{
  this->Mapper()->SetSampler(sampler);
}

void vtkMultiMaterialVolumeRepresentation::SetBackend(int backend)
{
  this->Mapper()->SetBackend(backend);
}

void vtkMultiMaterialVolumeRepresentation::SetNumberOfThreads(int threads)
{
  this->Mapper()->SetThreadsPerProcess(threads);
}

void vtkMultiMaterialVolumeRepresentation::SetExposure(double exposure)
{
  this->Mapper()->SetExposure(exposure);
}

void vtkMultiMaterialVolumeRepresentation::SetDenoisingMode(int mode)
{
  this->Mapper()->SetDenoisingMode(mode);
}

void vtkMultiMaterialVolumeRepresentation::SetLinearImageFile(const char* path)
{
  this->Mapper()->SetLinearImageFile(path);
}

void vtkMultiMaterialVolumeRepresentation::SetPreset(const char* name)
{
  const std::string value = name ? name : "";
  if (value == this->Preset)
    return;
  this->Preset = value;
  this->UpdateMaterialSource();
  this->Modified();
}

void vtkMultiMaterialVolumeRepresentation::SetSceneFile(const char* path)
{
  const std::string value = path ? path : "";
  if (value == this->SceneFile)
    return;
  this->SceneFile = value;
  this->UpdateMaterialSource();
  this->Modified();
}

// A scene file, else a preset, else ParaView's transfer functions (the
// mapper's translation of the volume property).
void vtkMultiMaterialVolumeRepresentation::UpdateMaterialSource()
{
  bool ok = true;
  if (!this->SceneFile.empty())
    ok = this->Materials->SetSceneFile(this->SceneFile.c_str());
  else if (!this->Preset.empty())
    ok = this->Materials->SetPreset(this->Preset.c_str());
  if (!ok)
  {
    // vtkMultiMaterialProperty said why; keep ParaView's functions.
    vtkErrorMacro("could not use " << (this->SceneFile.empty() ? "the preset \"" + this->Preset + "\""
                                                               : "the scene file " + this->SceneFile)
                                   << ": rendering ParaView's transfer functions");
  }
  const bool useMaterials = ok && (!this->SceneFile.empty() || !this->Preset.empty());
  this->Mapper()->SetMultiMaterialProperty(useMaterials ? this->Materials.Get() : nullptr);
}

void vtkMultiMaterialVolumeRepresentation::SetLabelMapArray(const char* name)
{
  const std::string value = name ? name : "";
  if (value == this->LabelMapArray)
    return;
  this->LabelMapArray = value;
  this->MarkModified(); // RequestData makes the mask
}

int vtkMultiMaterialVolumeRepresentation::GetAccumulatedSamples()
{
  return this->Mapper()->GetCombinedSamples();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfCombinedRenders()
{
  return this->Mapper()->GetNumberOfCombinedRenders();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfLocalRenders()
{
  return this->Mapper()->GetNumberOfLocalRenders();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfSceneBuilds()
{
  return this->Mapper()->GetNumberOfSceneBuilds();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfRefits()
{
  return this->Mapper()->GetNumberOfRefits();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfRestarts()
{
  return this->Mapper()->GetNumberOfRestarts();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfMajorantGridBuilds()
{
  return this->Mapper()->GetNumberOfMajorantGridBuilds();
}

int vtkMultiMaterialVolumeRepresentation::GetNumberOfMajorantGridRefits()
{
  return this->Mapper()->GetNumberOfMajorantGridRefits();
}

// Every process asks for the whole volume: each renders samples of the
// whole image (ParaView would otherwise give each its piece of the data).
int vtkMultiMaterialVolumeRepresentation::RequestUpdateExtent(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestUpdateExtent(request, inputVector, outputVector))
    return 0;
  for (int port = 0; port < this->GetNumberOfInputPorts(); ++port)
  {
    for (int i = 0; i < inputVector[port]->GetNumberOfInformationObjects(); ++i)
    {
      vtkInformation* info = inputVector[port]->GetInformationObject(i);
      info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
      info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
      info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
      if (info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
        info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
          info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
    }
  }
  return 1;
}

int vtkMultiMaterialVolumeRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  const int result = this->Superclass::RequestData(request, inputVector, outputVector);
  this->UpdateLabelMap();
  return result;
}

// The label map: the named point array as the mapper's mask, and for each
// label a material by the mapper's one label rule (the front ends' default
// label colour, opacity 1). ParaView's volume property is left as the user
// set it.
void vtkMultiMaterialVolumeRepresentation::UpdateLabelMap()
{
  vtkImageData* image = vtkImageData::SafeDownCast(this->Cache);
  vtkDataArray* labels =
    image && !this->LabelMapArray.empty() ? image->GetPointData()->GetArray(this->LabelMapArray.c_str()) : nullptr;
  if (!labels)
  {
    if (image && !this->LabelMapArray.empty())
      vtkWarningMacro("the input has no point array \"" << this->LabelMapArray << "\": no label map");
    this->Mapper()->SetMaskInput(nullptr);
    this->Mapper()->RemoveAllLabelMaterials();
    return;
  }
  if (labels->GetNumberOfComponents() != 1)
  {
    vtkWarningMacro("the label map array \"" << this->LabelMapArray << "\" has " << labels->GetNumberOfComponents()
                                             << " components, not 1: no label map");
    this->Mapper()->SetMaskInput(nullptr);
    this->Mapper()->RemoveAllLabelMaterials();
    return;
  }
  vtkNew<vtkImageData> mask;
  mask->CopyStructure(image);
  mask->GetPointData()->SetScalars(labels);
  vtkNew<vtkIdList> found;
  if (!vtkMultiMaterialVolumeMapper::GetLabelsPresent(mask, found))
  {
    vtkWarningMacro(
      "the label map array \"" << this->LabelMapArray << "\" does not hold whole-number labels: no label map");
    this->Mapper()->SetMaskInput(nullptr);
    this->Mapper()->RemoveAllLabelMaterials();
    return;
  }
  this->Mapper()->SetMaskInput(mask);
  this->Mapper()->SetMaskTypeToLabelMap();

  // Up to 64 labels (0 is the background): more is not a label map.
  if (found->GetNumberOfIds() > 64)
  {
    vtkWarningMacro(
      "the label map array \"" << this->LabelMapArray << "\" has more than 64 labels: only the first 64 are materials");
  }
  this->Mapper()->RemoveAllLabelMaterials();
  for (vtkIdType i = 0; i < std::min<vtkIdType>(found->GetNumberOfIds(), 64); ++i)
  {
    const int label = static_cast<int>(found->GetId(i));
    double c[3];
    vtkMultiMaterialVolumeMapper::GetDefaultLabelColor(label, c);
    this->Mapper()->SetLabelMaterial(label, c[0], c[1], c[2], 1.0);
  }
}

bool vtkMultiMaterialVolumeRepresentation::AddToView(vtkView* view)
{
  if (!this->Superclass::AddToView(view))
    return false;
  if (vtkPVRenderView* rview = vtkPVRenderView::SafeDownCast(view))
  {
    this->ObservedView = view;
    this->ObservedRenderer = rview->GetRenderer();
    this->StartRenderObserver = this->ObservedRenderer->AddObserver(
      vtkCommand::StartEvent, this, &vtkMultiMaterialVolumeRepresentation::OnStartRender);
  }
  return true;
}

bool vtkMultiMaterialVolumeRepresentation::RemoveFromView(vtkView* view)
{
  if (view == this->ObservedView)
  {
    if (this->ObservedRenderer)
      this->ObservedRenderer->RemoveObserver(this->StartRenderObserver);
    this->ObservedRenderer = nullptr;
    this->ObservedView = nullptr;
  }
  return this->Superclass::RemoveFromView(view);
}

// The processes agree whether all of them render this representation now.
// Every process that renders the view gets here (a renderer's StartEvent),
// hidden or not; with distributed rendering off, only one process renders
// and nothing is combined.
void vtkMultiMaterialVolumeRepresentation::OnStartRender()
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  vtkPVRenderView* view = vtkPVRenderView::SafeDownCast(this->ObservedView.GetPointer());
  if (!controller || controller->GetNumberOfProcesses() < 2 || !view || !view->GetUseDistributedRenderingForRender())
  {
    this->Mapper()->SetCombineThisRender(false);
    return;
  }
  vtkPVLODVolume* actor = this->GetRenderedProp();
  // This process renders the mapper when the actor is visible and draws
  // its full level of detail (not the outline).
  const int mine = this->GetVisibility() && actor && actor->GetVisibility() && !actor->GetEnableLOD() && this->Cache &&
      this->VolumeMapper->GetNumberOfInputConnections(0) > 0
    ? 1
    : 0;
  int all = 0;
  controller->AllReduce(&mine, &all, 1, vtkCommunicator::MIN_OP);
  this->Mapper()->SetCombineThisRender(all == 1);
  if (mine && !all)
  {
    vtkWarningMacro("some process does not render this representation (hidden there, its outline "
                    "drawn instead, or no data): this render shows this process's samples only");
  }
}

void vtkMultiMaterialVolumeRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Preset: \"" << this->Preset << "\"\n";
  os << indent << "SceneFile: \"" << this->SceneFile << "\"\n";
  os << indent << "LabelMapArray: \"" << this->LabelMapArray << "\"\n";
}
