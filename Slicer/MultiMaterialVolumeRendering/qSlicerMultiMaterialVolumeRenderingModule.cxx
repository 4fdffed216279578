#include "qSlicerMultiMaterialVolumeRenderingModule.h"

#include <vtkMRMLMultiMaterialVolumeRenderingPipeline.h>
#include <vtkSlicerMultiMaterialVolumeRenderingLogic.h>
#include <vtkSlicerVolumeRenderingLogic.h>

#include <vtkMRMLApplicationLogic.h>

class qSlicerMultiMaterialVolumeRenderingModulePrivate
{
};

qSlicerMultiMaterialVolumeRenderingModule::qSlicerMultiMaterialVolumeRenderingModule(QObject* parent)
  : Superclass(parent)
  , d_ptr(new qSlicerMultiMaterialVolumeRenderingModulePrivate)
{
}

qSlicerMultiMaterialVolumeRenderingModule::~qSlicerMultiMaterialVolumeRenderingModule() = default;

QString qSlicerMultiMaterialVolumeRenderingModule::helpText() const
{
  return tr("Adds the rendering method \"Path tracing (MM-RTM)\" to the Volume Rendering module: a physically based "
            "path tracer (multi-material radiative transfer, Xu et al. 2025) that refines while the view is idle. "
            "A segmentation set on the display node renders its segments as materials of their own.");
}

QString qSlicerMultiMaterialVolumeRenderingModule::acknowledgementText() const
{
  return tr("MM-RTM: Xu et al. 2025, \"Efficient Multi-Material Volume Rendering for Realistic Visualization with "
            "Complex Transfer Functions\".");
}

QStringList qSlicerMultiMaterialVolumeRenderingModule::contributors() const
{
  return QStringList() << QString("MM-RTM developers");
}

QStringList qSlicerMultiMaterialVolumeRenderingModule::categories() const
{
  return QStringList() << "Rendering";
}

QStringList qSlicerMultiMaterialVolumeRenderingModule::dependencies() const
{
  return QStringList() << "VolumeRendering"
                       << "Segmentations"
                       << "LayerDM";
}

void qSlicerMultiMaterialVolumeRenderingModule::setup()
{
  this->Superclass::setup();
  vtkMRMLMultiMaterialVolumeRenderingPipeline::RegisterPipelineCreator();
  auto* logic = vtkSlicerMultiMaterialVolumeRenderingLogic::SafeDownCast(this->logic());
  auto* volumeRendering =
    vtkSlicerVolumeRenderingLogic::SafeDownCast(this->appLogic()->GetModuleLogic("VolumeRendering"));
  if (logic && volumeRendering)
    logic->SetVolumeRenderingLogic(volumeRendering);
}

qSlicerAbstractModuleRepresentation* qSlicerMultiMaterialVolumeRenderingModule::createWidgetRepresentation()
{
  return nullptr; // no panel: the Volume Rendering module lists the method
}

vtkMRMLAbstractLogic* qSlicerMultiMaterialVolumeRenderingModule::createLogic()
{
  return vtkSlicerMultiMaterialVolumeRenderingLogic::New();
}
