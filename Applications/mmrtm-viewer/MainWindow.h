// The viewer's window: the path-traced view in the middle, the editors
// (materials' transfer functions, labels, render settings) in a dock, a
// status line with the image's progress. The image refines in small steps
// from the event loop (one render of SamplesPerRender samples per step), so
// the window stays responsive and an edit takes effect at the next step.
#pragma once

#include <QElapsedTimer>
#include <QMainWindow>
#include <functional>
#include <memory>

#include "ViewerScene.h"

class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QMenu;
class QTabWidget;
class QTimer;

namespace mmrtm::viewer {

class LabelTableWidget;
class RenderSettingsWidget;
class TransferFunctionEditor;
class VtkOpenGLWidget;

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;

  // Each returns false, after showing the error (a dialog naming the file
  // and the problem), when it fails; what was open before stays.
  bool openVolume(const QString& path);
  bool openLabels(const QString& path);
  bool openLabelTable(const QString& path);
  bool setPreset(const QString& name);
  bool loadScene(const QString& path);
  bool saveScene(const QString& path);
  bool saveImage(const QString& path);        // PNG of the view
  bool saveLinearImage(const QString& path);  // PFM of the accumulated radiance

  // How errors are shown and DICOM series chosen (tests replace them; by
  // default a QMessageBox and a SeriesChooserDialog). The chooser returns
  // the chosen SeriesInfo::key(), empty to cancel.
  void setErrorHandler(std::function<void(const QString&)> handler) { showError_ = std::move(handler); }
  void setSeriesChooser(std::function<QString(const QString&, const QVector<SeriesInfo>&)> chooser) {
    chooseSeries_ = std::move(chooser);
  }

  // Brings an editor to the front: "materials", "labels" or "render".
  void showEditor(const QString& name);

  ViewerScene& scene() { return *scene_; }
  VtkOpenGLWidget* view() { return view_; }
  TransferFunctionEditor* transferFunctionEditor() { return editor_; }
  LabelTableWidget* labelTable() { return labels_; }
  RenderSettingsWidget* renderSettings() { return settings_; }
  QLabel* statusLine() { return status_; }

 protected:
  void dragEnterEvent(QDragEnterEvent* event) override;
  void dropEvent(QDropEvent* event) override;
  void closeEvent(QCloseEvent* event) override;

 private:
  void buildMenus();
  QWidget* buildMaterialsPanel();
  void showScene();     // the editors from the scene, the camera fitted
  void showMaterial();  // the editor from the chosen material
  void applyEditor(bool interactive);
  void scheduleRender();  // another refinement step, unless converged
  void onRendered();
  void updateStatus();

  std::unique_ptr<ViewerScene> scene_;
  VtkOpenGLWidget* view_ = nullptr;
  TransferFunctionEditor* editor_ = nullptr;
  QComboBox* material_ = nullptr;
  QDoubleSpinBox *pointValue_ = nullptr, *pointOpacity_ = nullptr;
  LabelTableWidget* labels_ = nullptr;
  RenderSettingsWidget* settings_ = nullptr;
  QLabel* status_ = nullptr;
  QTabWidget* tabs_ = nullptr;
  QMenu* presets_ = nullptr;
  QTimer* refine_ = nullptr;
  QElapsedTimer sinceRestart_;
  int samplesAtRestart_ = 0;
  bool editing_ = false;  // a transfer-function point is being dragged
  QString renderError_;   // the mapper's error at the last render
  std::function<void(const QString&)> showError_;
  std::function<QString(const QString&, const QVector<SeriesInfo>&)> chooseSeries_;
};

}  // namespace mmrtm::viewer
