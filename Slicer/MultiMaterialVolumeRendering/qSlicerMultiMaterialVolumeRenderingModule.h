// The loadable module of the extension route (a Slicer build): it has no
// panel of its own; it adds "Path tracing (MM-RTM)" to the Volume Rendering
// module's methods and the pipeline that renders it to the 3D views.
// Settings are on the display node (Python console, or a saved scene).
#ifndef __qSlicerMultiMaterialVolumeRenderingModule_h
#define __qSlicerMultiMaterialVolumeRenderingModule_h

#include "qSlicerLoadableModule.h"

#include "qSlicerMultiMaterialVolumeRenderingModuleExport.h"

class qSlicerMultiMaterialVolumeRenderingModulePrivate;

class Q_SLICER_QTMODULES_MULTIMATERIALVOLUMERENDERING_EXPORT qSlicerMultiMaterialVolumeRenderingModule
  : public qSlicerLoadableModule
{
  Q_OBJECT
  Q_PLUGIN_METADATA(IID "org.slicer.modules.loadable.qSlicerLoadableModule/1.0");
  Q_INTERFACES(qSlicerLoadableModule);

public:
  typedef qSlicerLoadableModule Superclass;
  explicit qSlicerMultiMaterialVolumeRenderingModule(QObject* parent = nullptr);
  ~qSlicerMultiMaterialVolumeRenderingModule() override;

  qSlicerGetTitleMacro(tr("Multi-Material Volume Rendering"));

  QString helpText() const override;
  QString acknowledgementText() const override;
  QStringList contributors() const override;
  QStringList categories() const override;
  QStringList dependencies() const override;
  bool isHidden() const override { return true; }

protected:
  void setup() override;
  qSlicerAbstractModuleRepresentation* createWidgetRepresentation() override;
  vtkMRMLAbstractLogic* createLogic() override;

protected:
  QScopedPointer<qSlicerMultiMaterialVolumeRenderingModulePrivate> d_ptr;

private:
  Q_DECLARE_PRIVATE(qSlicerMultiMaterialVolumeRenderingModule);
  Q_DISABLE_COPY(qSlicerMultiMaterialVolumeRenderingModule);
};

#endif
