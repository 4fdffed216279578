#include "MainWindow.h"

#include <QAction>
#include <QCloseEvent>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QImage>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QStatusBar>
#include <QTabWidget>
#include <QTimer>
#include <QVBoxLayout>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkFloatArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkRenderer.h>
#include <vector>

#include "LabelTableWidget.h"
#include "RenderSettingsWidget.h"
#include "TransferFunctionEditor.h"
#include "VtkOpenGLWidget.h"
#include "image_io.h"
#include "vtkMultiMaterialVolumeMapper.h"

namespace mmrtm::viewer {
namespace {
// How often a pass running in the background is looked at.
constexpr int kPollMilliseconds = 15;
}  // namespace

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), scene_(std::make_unique<ViewerScene>()) {
  setWindowTitle(tr("MM-RTM viewer"));
  setAcceptDrops(true);
  view_ = new VtkOpenGLWidget;
  setCentralWidget(view_);

  auto* tabs = tabs_ = new QTabWidget;
  tabs->addTab(buildMaterialsPanel(), tr("Materials"));
  labels_ = new LabelTableWidget;
  tabs->addTab(labels_, tr("Labels"));
  settings_ = new RenderSettingsWidget;
  tabs->addTab(settings_, tr("Render"));
  tabs->setMinimumWidth(340);
  auto* dock = new QDockWidget(tr("Editors"));
  dock->setObjectName("editors");
  dock->setWidget(tabs);
  dock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  addDockWidget(Qt::RightDockWidgetArea, dock);
  resizeDocks({dock}, {400}, Qt::Horizontal);  // the view takes the rest

  status_ = new QLabel(tr("Open a volume (File menu, or drop a file here)."));
  statusBar()->addWidget(status_, 1);
  buildMenus();

  showError_ = [this](const QString& message) { QMessageBox::critical(this, tr("MM-RTM viewer"), message); };
  chooseSeries_ = [this](const QString& folder, const QVector<SeriesInfo>& series) {
    SeriesChooserDialog dialog(folder, series, this);
    return dialog.exec() == QDialog::Accepted ? dialog.chosenKey() : QString();
  };

  // A description the tracer refuses (a scene file's error) is named in the
  // status line; the last good image stays.
  auto onError = vtkSmartPointer<vtkCallbackCommand>::New();
  onError->SetClientData(this);
  onError->SetCallback([](vtkObject*, unsigned long, void* self, void* call) {
    auto* w = static_cast<MainWindow*>(self);
    QString message = QString::fromUtf8(call ? static_cast<const char*>(call) : "");
    message = message.mid(message.indexOf("): ") + 3).trimmed();
    w->renderError_ = message;
  });
  scene_->Mapper()->AddObserver(vtkCommand::ErrorEvent, onError);

  refine_ = new QTimer(this);
  refine_->setSingleShot(true);
  // A refinement step: a repaint, unless a pass still runs in the
  // background (then only a look later: the event loop does no work).
  connect(refine_, &QTimer::timeout, this, [this] {
    if (scene_->Mapper()->IsRefining())
      refine_->start(kPollMilliseconds);
    else
      view_->update();
  });
  connect(view_, &VtkOpenGLWidget::rendered, this, &MainWindow::onRendered);
  connect(view_, &VtkOpenGLWidget::cameraChanged, this, [this] { sinceRestart_.restart(), samplesAtRestart_ = 0; });
  connect(editor_, &TransferFunctionEditor::edited, this, &MainWindow::applyEditor);
  connect(editor_, &TransferFunctionEditor::selectionChanged, this, [this](int point) {
    const bool has = point >= 0;
    pointValue_->setEnabled(has);
    pointOpacity_->setEnabled(has);
    if (!has) return;
    const QSignalBlocker b1(pointValue_), b2(pointOpacity_);
    pointValue_->setValue(editor_->points()[point].x());
    pointOpacity_->setValue(editor_->points()[point].y());
  });
  connect(labels_, &LabelTableWidget::labelEdited, this, [this](int row) {
    scene_->SetLabel(labels_->labels()[row]);
    scheduleRender();
  });
  connect(settings_, &RenderSettingsWidget::settingsChanged, this, [this] {
    scene_->SetSettings(settings_->settings());
    scheduleRender();
  });
  resize(1280, 800);
}

MainWindow::~MainWindow() { refine_->stop(); }

QWidget* MainWindow::buildMaterialsPanel() {
  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  material_ = new QComboBox;
  auto* form = new QFormLayout;
  form->addRow(tr("Material"), material_);
  layout->addLayout(form);
  editor_ = new TransferFunctionEditor;
  layout->addWidget(editor_, 1);
  auto* numbers = new QHBoxLayout;
  pointValue_ = new QDoubleSpinBox;
  pointValue_->setRange(-1e9, 1e9);
  pointValue_->setDecimals(1);
  pointOpacity_ = new QDoubleSpinBox;
  pointOpacity_->setRange(0, 1);
  pointOpacity_->setSingleStep(0.05);
  pointOpacity_->setDecimals(3);
  pointValue_->setEnabled(false);
  pointOpacity_->setEnabled(false);
  numbers->addWidget(new QLabel(tr("Point: value")));
  numbers->addWidget(pointValue_);
  numbers->addWidget(new QLabel(tr("density")));
  numbers->addWidget(pointOpacity_);
  layout->addLayout(numbers);
  auto* help =
      new QLabel(tr("Click: add a point; drag: move; right click or Delete: remove. "
                    "Colour bar: double click to add or recolour a stop, right click to remove."));
  help->setWordWrap(true);
  layout->addWidget(help);
  auto numeric = [this] { editor_->setSelectedPoint(pointValue_->value(), pointOpacity_->value()); };
  connect(pointValue_, &QDoubleSpinBox::editingFinished, this, numeric);
  connect(pointOpacity_, &QDoubleSpinBox::editingFinished, this, numeric);
  connect(material_, &QComboBox::currentIndexChanged, this, [this] { showMaterial(); });
  return panel;
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(tr("&Open volume..."), QKeySequence::Open, this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Open a volume"), QString(),
        tr("Volumes (*.nrrd *.nhdr *.nii *.nii.gz *.mha *.mhd *.vti *.vtk *.inv3);;All files (*)"));
    if (!path.isEmpty()) openVolume(path);
  });
  file->addAction(tr("Open &DICOM folder..."), this, [this] {
    const QString path = QFileDialog::getExistingDirectory(this, tr("Open a DICOM folder"));
    if (!path.isEmpty()) openVolume(path);
  });
  file->addAction(tr("Open &label map..."), this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Open a label map"));
    if (!path.isEmpty()) openLabels(path);
  });
  file->addAction(tr("Open label &table..."), this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Open a label table"), QString(),
                                                      tr("Label tables (*.txt *.ctbl);;All files (*)"));
    if (!path.isEmpty()) openLabelTable(path);
  });
  file->addSeparator();
  file->addAction(tr("&Load scene..."), this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Load a scene"), QString(), tr("Scenes (*.json)"));
    if (!path.isEmpty()) loadScene(path);
  });
  file->addAction(tr("&Save scene..."), QKeySequence::Save, this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save the scene"), QString(), tr("Scenes (*.json)"));
    if (!path.isEmpty()) saveScene(path);
  });
  file->addAction(tr("Save &image..."), this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save the image"), QString(), tr("PNG (*.png)"));
    if (!path.isEmpty()) saveImage(path);
  });
  file->addAction(tr("Save linear image (&PFM)..."), this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save the linear image"), QString(), tr("PFM (*.pfm)"));
    if (!path.isEmpty()) saveLinearImage(path);
  });
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);
  presets_ = menuBar()->addMenu(tr("&Presets"));
  for (const std::string& name : ViewerScene::PresetNames()) {
    const QString preset = QString::fromStdString(name);
    presets_->addAction(preset, this, [this, preset] { setPreset(preset); });
  }
  QMenu* viewMenu = menuBar()->addMenu(tr("&View"));
  viewMenu->addAction(tr("&Reset camera"), QKeySequence(Qt::Key_R), this, [this] { view_->ResetCamera(); });
}

// Each of the file operations: the scene throws with a message naming the
// file and the problem, which is shown; what was open stays.
namespace {
template <typename Operation>
bool Attempt(const std::function<void(const QString&)>& showError, Operation operation) {
  try {
    operation();
    return true;
  } catch (const std::exception& e) {
    showError(QString::fromStdString(e.what()));
    return false;
  }
}
}  // namespace

bool MainWindow::openVolume(const QString& path) {
  QString series;
  if (QFileInfo(path).isDir()) {
    QVector<SeriesInfo> list;
    if (!Attempt(showError_, [&] { list = ViewerScene::ListSeries(path.toStdString()); })) return false;
    if (list.size() > 1) {
      series = chooseSeries_(path, list);
      if (series.isEmpty()) return false;  // cancelled
    }
  }
  if (!Attempt(showError_, [&] { scene_->OpenVolume(path.toStdString(), series.toStdString()); })) return false;
  if (!view_->Renderer()->HasViewProp(scene_->Volume())) view_->Renderer()->AddVolume(scene_->Volume());
  setWindowTitle(tr("MM-RTM viewer - %1").arg(QFileInfo(path).fileName()));
  showScene();
  view_->ResetCamera();
  return true;
}

bool MainWindow::openLabels(const QString& path) {
  if (!Attempt(showError_, [&] { scene_->OpenLabels(path.toStdString()); })) return false;
  showScene();
  return true;
}

bool MainWindow::openLabelTable(const QString& path) {
  if (!Attempt(showError_, [&] { scene_->OpenLabelTable(path.toStdString()); })) return false;
  showScene();
  return true;
}

bool MainWindow::setPreset(const QString& name) {
  if (!Attempt(showError_, [&] { scene_->SetPreset(name.toStdString()); })) return false;
  showScene();
  return true;
}

bool MainWindow::loadScene(const QString& path) {
  if (!Attempt(showError_, [&] { scene_->LoadScene(path.toStdString()); })) return false;
  if (!view_->Renderer()->HasViewProp(scene_->Volume())) view_->Renderer()->AddVolume(scene_->Volume());
  showScene();
  const nlohmann::json& saved = scene_->SceneCamera();
  if (saved.empty()) {
    view_->ResetCamera();
  } else {  // the scene's own view
    vtkCamera* camera = view_->Renderer()->GetActiveCamera();
    const auto v = [&](const char* key) { return saved[key].get<std::vector<double>>(); };
    camera->SetPosition(v("position").data());
    camera->SetFocalPoint(v("look_at").data());
    if (saved.contains("up")) camera->SetViewUp(v("up").data());
    if (saved.contains("fov")) camera->SetViewAngle(saved["fov"].get<double>());
    const bool orthographic = saved.value("projection", "perspective") == "orthographic";
    camera->SetParallelProjection(orthographic);
    if (orthographic) camera->SetParallelScale(0.5 * saved.value("ortho_height", 2 * camera->GetParallelScale()));
    view_->Renderer()->ResetCameraClippingRange();
    view_->update();
  }
  return true;
}

bool MainWindow::saveScene(const QString& path) {
  const int* size = view_->RenderWindow()->GetSize();
  return Attempt(showError_, [&] {
    scene_->SaveScene(path.toStdString(), view_->Renderer()->GetActiveCamera(), size[0], size[1]);
  });
}

bool MainWindow::saveImage(const QString& path) {
  const QImage image = view_->grabFramebuffer();
  if (image.isNull() || !image.save(path, "PNG")) {
    showError_(tr("%1: the image could not be written").arg(path));
    return false;
  }
  return true;
}

bool MainWindow::saveLinearImage(const QString& path) {
  return Attempt(showError_, [&] {
    vtkNew<vtkImageData> image;
    scene_->Mapper()->GetAccumulatedImage(image);
    if (image->GetNumberOfPoints() == 0) throw std::runtime_error("nothing rendered yet");
    int dims[3];
    image->GetDimensions(dims);
    RGBImage out{dims[0], dims[1], std::vector<RGB>(size_t(dims[0]) * dims[1])};
    auto* values = vtkFloatArray::SafeDownCast(image->GetPointData()->GetScalars());
    for (int y = 0; y < dims[1]; ++y)  // PFM rows as the film's: row 0 at the top
      for (int x = 0; x < dims[0]; ++x) {
        const float* v = values->GetPointer(4 * (vtkIdType(dims[1] - 1 - y) * dims[0] + x));
        out.pixels[size_t(y) * dims[0] + x] = RGB(v[0], v[1], v[2]);
      }
    WritePFM(path.toStdString(), out);
  });
}

void MainWindow::showScene() {
  const QSignalBlocker block(material_);
  material_->clear();
  for (const std::string& name : scene_->MaterialNames()) material_->addItem(QString::fromStdString(name));
  double low = 0, high = 1;
  const QVector<double> histogram = scene_->Histogram(128, low, high);
  editor_->setRange(low, high);
  editor_->setHistogram(histogram);
  showMaterial();
  labels_->setLabels(scene_->Labels());
  settings_->setSettings(scene_->Settings());
  sinceRestart_.restart();
  samplesAtRestart_ = 0;
  scheduleRender();
}

void MainWindow::showMaterial() {
  const std::string material = material_->currentText().toStdString();
  if (material.empty()) return;
  editor_->setPoints(scene_->DensityPoints(material));
  editor_->setStops(scene_->AlbedoStops(material));
}

// While a point is dragged the mapper draws its preview (the interactive
// frame rate); on release the image refines again.
void MainWindow::applyEditor(bool interactive) {
  const std::string material = material_->currentText().toStdString();
  if (material.empty()) return;
  scene_->SetDensityPoints(material, editor_->points());
  scene_->SetAlbedoStops(material, editor_->stops());
  scene_->Apply();
  editing_ = interactive;
  view_->RenderWindow()->SetDesiredUpdateRate(interactive ? 15.0 : 0.0001);
  sinceRestart_.restart();
  samplesAtRestart_ = 0;
  if (const int point = editor_->selectedPoint(); point >= 0) {
    const QSignalBlocker b1(pointValue_), b2(pointOpacity_);
    pointValue_->setValue(editor_->points()[point].x());
    pointOpacity_->setValue(editor_->points()[point].y());
  }
  scheduleRender();
}

void MainWindow::scheduleRender() {
  if (scene_->HasVolume()) refine_->start(0);
}

void MainWindow::onRendered() {
  const bool failed = !renderError_.isEmpty();
  updateStatus();
  if (failed) return;  // no refinement of a scene the tracer refuses; the next edit tries again
  // Keep refining while the image is not converged and nothing is dragged:
  // at once after a synchronous pass, a little later while a pass runs in
  // the background (to draw its samples when it is done).
  vtkMultiMaterialVolumeMapper* m = scene_->Mapper();
  if (scene_->HasVolume() && !view_->Interacting() && !editing_ && !m->IsConverged())
    refine_->start(m->IsRefining() ? kPollMilliseconds : 0);
}

void MainWindow::updateStatus() {
  if (!renderError_.isEmpty()) {
    status_->setText(tr("<span style='color:#d04040'>%1</span>").arg(renderError_.toHtmlEscaped()));
    renderError_.clear();
    return;
  }
  vtkMultiMaterialVolumeMapper* m = scene_->Mapper();
  const int samples = m->GetAccumulatedSamples();
  const int* size = view_->RenderWindow()->GetSize();
  const double seconds = sinceRestart_.isValid() ? sinceRestart_.elapsed() / 1000.0 : 0;
  const double rate = seconds > 0 ? double(samples - samplesAtRestart_) * size[0] * size[1] / seconds : 0;
  const QString denoiser =
      m->GetNumberOfDenoises() ? tr("   denoiser %1 s").arg(m->GetDenoisingSeconds(), 0, 'f', 1) : QString();
  status_->setText(tr("%1 samples/pixel   shown: %2   %3 Msamples/s   last refit %4 ms%5   %6%7")
                       .arg(samples)
                       .arg(QString::fromUtf8(m->GetDisplayStatus()))
                       .arg(rate / 1e6, 0, 'f', 2)
                       .arg(m->GetLastRefitSeconds() * 1000, 0, 'f', 1)
                       .arg(denoiser)
                       .arg(QString::fromUtf8(m->GetBackendDescription()))
                       .arg(m->IsConverged() ? tr("   (converged)") : QString()));
}

void MainWindow::showEditor(const QString& name) {
  const QStringList names{"materials", "labels", "render"};
  if (names.contains(name.toLower())) tabs_->setCurrentIndex(names.indexOf(name.toLower()));
}

void MainWindow::dragEnterEvent(QDragEnterEvent* event) {
  if (event->mimeData()->hasUrls()) event->acceptProposedAction();
}

// A dropped scene (.json) loads it; a second file while a volume is open
// and whose name says "label" is its label map; anything else is a volume.
void MainWindow::dropEvent(QDropEvent* event) {
  const QList<QUrl> urls = event->mimeData()->urls();
  if (urls.isEmpty()) return;
  const QString path = urls.first().toLocalFile();
  if (path.endsWith(".json", Qt::CaseInsensitive))
    loadScene(path);
  else if (scene_->HasVolume() && QFileInfo(path).fileName().contains("label", Qt::CaseInsensitive))
    openLabels(path);
  else
    openVolume(path);
  event->acceptProposedAction();
}

void MainWindow::closeEvent(QCloseEvent* event) {
  refine_->stop();  // no refinement step after the window is gone
  QMainWindow::closeEvent(event);
}

}  // namespace mmrtm::viewer
