// QTest of mmrtm-viewer, run under Xvfb (the xcb platform: Qt 6.4's
// offscreen platform has no QOpenGLWidget): the window as a user drives it,
// with the mouse on the transfer-function editor and the label table, and
// the files of ../shared/data.
#include <QApplication>
#include <QDir>
#include <QFile>
#include <QImage>
#include <QJsonDocument>
#include <QLabel>
#include <QProcess>
#include <QSurfaceFormat>
#include <QTemporaryDir>
#include <QtTest>

#include <vtkCamera.h>
#include <vtkFloatArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkRenderer.h>

#include <cmath>
#include <filesystem>

#include "LabelTableWidget.h"
#include "MainWindow.h"
#include "RenderSettingsWidget.h"
#include "TransferFunctionEditor.h"
#include "VtkOpenGLWidget.h"
#include "image_io.h"
#include "vtkMultiMaterialVolumeMapper.h"

namespace fs = std::filesystem;
using mmrtm::viewer::MainWindow;

namespace {
QString Data(const char* name) { return QString(MMRTM_SHARED_DATA_DIR) + "/" + name; }

// Processes events (the window refines by itself) until the image has
// `samples` samples per pixel.
bool RefineTo(MainWindow& w, int samples, int timeoutMs = 120000) {
  return QTest::qWaitFor([&] { return w.scene().Mapper()->GetAccumulatedSamples() >= samples; }, timeoutMs);
}

// The view's pixels as the user sees them.
QImage View(MainWindow& w) { return w.view()->grabFramebuffer().convertToFormat(QImage::Format_RGB888); }

double Coverage(const QImage& image) {
  // Pixels that differ from the view's background (0.08, 0.08, 0.1).
  int covered = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const QColor c = image.pixelColor(x, y);
      covered += std::abs(c.red() - 20) + std::abs(c.green() - 20) + std::abs(c.blue() - 26) > 30;
    }
  return double(covered) / (image.width() * image.height());
}

double MeanDifference(const QImage& a, const QImage& b) {
  double sum = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const QColor p = a.pixelColor(x, y), q = b.pixelColor(x, y);
      sum += std::abs(p.red() - q.red()) + std::abs(p.green() - q.green()) + std::abs(p.blue() - q.blue());
    }
  return sum / (3.0 * 255 * a.width() * a.height());
}

// A window of a fixed size with fast settings: the same seed every time.
// The view shows the unbiased image (its pixels are compared exactly)
// unless a test asks for a denoised display.
struct Viewer {
  MainWindow window;
  QString error;
  explicit Viewer(int denoising = 0) {
    window.setErrorHandler([this](const QString& message) { error = message; });
    window.resize(1000, 640);
    window.show();
    mmrtm::viewer::RenderSettings s = window.renderSettings()->settings();
    s.samplesPerRender = 2;
    s.maximumSamples = 8;
    s.denoising = denoising;
    window.renderSettings()->setSettings(s);
    window.scene().SetSettings(s);
    exposed = QTest::qWaitForWindowExposed(&window);
  }
  bool exposed = false;
};
}  // namespace

class TestMmrtmViewer : public QObject {
  Q_OBJECT

 private slots:
  void opensTheHeadCtAndShowsAnImage() {
    Viewer v;
    QVERIFY(v.exposed);
    QElapsedTimer timer;
    timer.start();
    QVERIFY(v.window.openVolume(Data("ct_head_cranium.nrrd")));
    QVERIFY2(v.error.isEmpty(), qPrintable(v.error));
    QVERIFY(RefineTo(v.window, 8, 60000));
    const double coverage = Coverage(View(v.window));
    qInfo("head CT: 8 samples per pixel after %lld ms; coverage %.3f", timer.elapsed(), coverage);
    QVERIFY2(coverage > 0.05 && coverage < 0.9, "a blank or full view");
    QVERIFY(v.window.statusLine()->text().contains("8 samples/pixel"));
  }

  void draggingAPointRefitsRestartsAndReleaseRefines() {
    Viewer v;
    QVERIFY(v.window.openVolume(Data("ct_head_cranium.nrrd")));
    QVERIFY(RefineTo(v.window, 8));
    const QImage before = View(v.window);
    vtkMultiMaterialVolumeMapper* m = v.window.scene().Mapper();
    const int refits = m->GetNumberOfRefits(), restarts = m->GetNumberOfRestarts(),
              grids = m->GetNumberOfMajorantGridBuilds();
    mmrtm::viewer::TransferFunctionEditor* editor = v.window.transferFunctionEditor();
    // The ct-bone density curve's middle point, dragged to the right (less bone).
    QCOMPARE(editor->points().size(), 3);
    const QPoint from = editor->pointPosition(1);
    QTest::mousePress(editor, Qt::LeftButton, {}, from);
    QTest::mouseMove(editor, from + QPoint(40, 0));
    QCOMPARE(editor->points()[1].x() > 300, true);
    QTest::qWait(300);                             // the preview renders while the button is held
    QCOMPARE(m->GetNumberOfRefits(), refits + 1);  // one change, one refit and one restart
    QCOMPARE(m->GetNumberOfRestarts(), restarts + 1);
    QCOMPARE(m->GetAccumulatedSamples(), 0);  // previews do not accumulate
    const double dragged = editor->points()[1].x();
    QTest::mouseMove(editor, from + QPoint(20, 0));  // back a little
    QVERIFY(editor->points()[1].x() < dragged);
    QTest::qWait(300);
    QCOMPARE(m->GetNumberOfRefits(), refits + 2);
    QCOMPARE(m->GetNumberOfRestarts(), restarts + 2);
    QTest::mouseMove(editor, from + QPoint(20, 0));  // no change: the description is the one the mapper has
    QTest::qWait(300);
    QCOMPARE(m->GetNumberOfRefits(), refits + 2);
    QCOMPARE(m->GetNumberOfRestarts(), restarts + 2);
    QTest::mouseRelease(editor, Qt::LeftButton, {}, from + QPoint(20, 0));
    QVERIFY(RefineTo(v.window, 8));
    QCOMPARE(m->GetNumberOfMajorantGridBuilds(), grids);  // refits only: the summaries were kept
    QVERIFY2(MeanDifference(before, View(v.window)) > 0.002, "the image changed");
  }

  // The settings panel sends the whole settings on every edit: sent again
  // unchanged, they must keep the accumulation, and so must an exposure
  // change (only drawing reads it). Catches a change guard that never
  // matches (one compared compact with indented JSON: every edit refitted
  // and restarted) and an exposure edit that restarts.
  void unchangedSettingsAndExposureKeepTheAccumulation() {
    Viewer v;
    QVERIFY(v.window.openVolume(Data("ct_head_cranium.nrrd")));
    QVERIFY(RefineTo(v.window, 8));
    vtkMultiMaterialVolumeMapper* m = v.window.scene().Mapper();
    const int refits = m->GetNumberOfRefits(), restarts = m->GetNumberOfRestarts();
    const QImage before = View(v.window);
    emit v.window.renderSettings()->settingsChanged();
    QTest::qWait(300);  // the render the edit schedules
    QCOMPARE(m->GetNumberOfRefits(), refits);
    QCOMPARE(m->GetNumberOfRestarts(), restarts);
    QCOMPARE(m->GetAccumulatedSamples(), 8);

    mmrtm::viewer::RenderSettings s = v.window.renderSettings()->settings();
    s.exposure *= 2;
    v.window.renderSettings()->setSettings(s);
    emit v.window.renderSettings()->settingsChanged();
    QTest::qWait(300);
    QCOMPARE(m->GetExposure(), s.exposure);
    QCOMPARE(m->GetNumberOfRestarts(), restarts);
    QCOMPARE(m->GetAccumulatedSamples(), 8);
    QVERIFY2(MeanDifference(before, View(v.window)) > 0.01, "the exposure brightened the image");
  }

  void hidingALabelChangesItsPixelsOnly() {
    Viewer v;
    QVERIFY(v.window.setPreset("ct-organs"));
    QVERIFY(v.window.openVolume(Data("ct_abdomen.nii.gz")));
    QVERIFY(v.window.openLabels(Data("ct_abdomen_labels.nii.gz")));
    QVERIFY(v.window.openLabelTable(Data("ct_abdomen_labels.txt")));
    QVERIFY2(v.error.isEmpty(), qPrintable(v.error));
    mmrtm::viewer::LabelTableWidget* table = v.window.labelTable();
    int liver = -1;
    for (int row = 0; row < table->labels().size(); ++row)
      if (table->labels()[row].name == "liver") liver = row;
    QVERIFY(liver >= 0);
    mmrtm::viewer::LabelEntry entry = table->labels()[liver];
    entry.color = QColor(0, 0, 255);
    entry.opacity = 0.8;
    table->setLabel(liver, entry);
    // The edited label reaches the mapper by its one label route
    // (SetLabelMaterial, as Slicer's segments and ParaView's labels do), and
    // the saved scene as a class of its own by the one label rule: density
    // 2.5/mm times its opacity, its colour as albedo.
    double rgbo[4] = {-1, -1, -1, -1};
    QVERIFY(v.window.scene().Mapper()->GetLabelMaterial(entry.id, rgbo));
    QCOMPARE(rgbo[2], 1.0);
    QCOMPARE(rgbo[3], 0.8);
    auto labelMaterial = [&] {
      const nlohmann::json description = v.window.scene().SavedDescription();
      for (const nlohmann::json& c : description["label_materials"]["classes"])
        if (c.value("ids", nlohmann::json::array()) == nlohmann::json::array({entry.id})) return c["material"];
      return nlohmann::json();
    };
    QCOMPARE(labelMaterial()["density"].get<double>(),
             0.8 * vtkMultiMaterialVolumeMapper::GetLabelDensityAtFullOpacity());
    QCOMPARE(labelMaterial()["albedo"], nlohmann::json::array({0.0, 0.0, 1.0}));
    QVERIFY(RefineTo(v.window, 8));
    const QImage before = View(v.window);
    vtkMultiMaterialVolumeMapper* m = v.window.scene().Mapper();
    const int restarts = m->GetNumberOfRestarts();
    entry.visible = false;
    table->setLabel(liver, entry);
    QCOMPARE(labelMaterial()["density"].get<double>(), 0.0);
    QVERIFY(v.window.scene().Mapper()->GetLabelMaterial(entry.id, rgbo));
    QCOMPARE(rgbo[3], 0.0);
    // The edit reaches the mapper at its next render, which may wait for a
    // pass in flight: until it restarts, the count of 8 is the old image's.
    QVERIFY2(QTest::qWaitFor([&] { return m->GetNumberOfRestarts() > restarts; }, 120000), "hiding restarts");
    QVERIFY(RefineTo(v.window, 8));
    const QImage after = View(v.window);
    // The liver's pixels (blue before) change; the others, far from it, do not.
    int blue = 0, blueChanged = 0, others = 0, othersChanged = 0;
    for (int y = 2; y < before.height() - 2; ++y)
      for (int x = 2; x < before.width() - 2; ++x) {
        bool nearBlue = false;
        for (int dy = -2; dy <= 2 && !nearBlue; ++dy)
          for (int dx = -2; dx <= 2 && !nearBlue; ++dx) {
            const QColor c = before.pixelColor(x + dx, y + dy);
            nearBlue = c.blue() > c.red() + 30 && c.blue() > c.green() + 30;
          }
        const QColor p = before.pixelColor(x, y), q = after.pixelColor(x, y);
        const bool changed =
            std::abs(p.red() - q.red()) + std::abs(p.green() - q.green()) + std::abs(p.blue() - q.blue()) > 24;
        const QColor c = p;
        if (c.blue() > c.red() + 30 && c.blue() > c.green() + 30) {
          ++blue;
          blueChanged += changed;
        } else if (!nearBlue) {
          ++others;
          othersChanged += changed;
        }
      }
    qInfo("liver pixels %d (%d changed), other pixels %d (%d changed)", blue, blueChanged, others, othersChanged);
    QVERIFY2(blue > 200, "the blue liver shows");
    QVERIFY2(blueChanged > 0.8 * blue, "hidden: the liver's pixels change");
    QVERIFY2(othersChanged < 0.05 * others, "the other pixels do not");
  }

  void aFolderWithTwoSeriesOpensTheChooser() {
    // Two series in one folder: the chest series, and the abdomen's JPEG 2000 one.
    QTemporaryDir folder;
    for (const auto& source : {Data("ct_chest_dicom"), Data("ct_abdomen_dicom_j2k")})
      for (const auto& entry : fs::directory_iterator(source.toStdString()))
        fs::copy_file(entry.path(),
                      fs::path(folder.path().toStdString()) /
                          (QFileInfo(source).fileName().toStdString() + "_" + entry.path().filename().string()));
    Viewer v;
    QVector<mmrtm::viewer::SeriesInfo> offered;
    v.window.setSeriesChooser([&](const QString&, const QVector<mmrtm::viewer::SeriesInfo>& series) {
      offered = series;
      for (const auto& s : series)
        if (s.slices == 20) return s.key();  // the abdomen's 20 slices
      return QString();
    });
    QVERIFY2(v.window.openVolume(folder.path()), qPrintable(v.error));
    QCOMPARE(offered.size(), 2);
    int dims[3];
    vtkImageData::SafeDownCast(v.window.scene().Mapper()->GetInput())->GetDimensions(dims);
    QCOMPARE(dims[2], 20);
    QVERIFY2(v.error.isEmpty(), qPrintable(v.error));
    // The real chooser lists both and returns the chosen series' key.
    mmrtm::viewer::SeriesChooserDialog dialog(folder.path(), offered);
    dialog.choose(1);
    QCOMPARE(dialog.chosenKey(), offered[1].key());
  }

  void aBrokenFileShowsTheErrorAndKeepsTheVolume() {
    Viewer v;
    QVERIFY(v.window.openVolume(Data("ct_head_cranium.nrrd")));
    QVERIFY(RefineTo(v.window, 4));
    QTemporaryDir folder;
    const QString broken = folder.filePath("broken.nrrd");
    QFile source(Data("ct_head_cranium.nrrd"));
    QVERIFY(source.open(QIODevice::ReadOnly));
    QFile out(broken);
    QVERIFY(out.open(QIODevice::WriteOnly));
    out.write(source.read(4096));  // the header and a sliver of the data
    out.close();
    QVERIFY(!v.window.openVolume(broken));
    QVERIFY2(v.error.contains("broken.nrrd"), qPrintable(v.error));
    QVERIFY(v.window.scene().VolumePath().find("ct_head_cranium.nrrd") != std::string::npos);
    v.error.clear();
    // A label map far from the volume (4 x 4 x 4 voxels 10 m away).
    const QString far = folder.filePath("far_labels.nrrd");
    QFile labels(far);
    QVERIFY(labels.open(QIODevice::WriteOnly));
    labels.write(
        "NRRD0004\ntype: uchar\ndimension: 3\nspace: left-posterior-superior\nsizes: 4 4 4\n"
        "space directions: (1,0,0) (0,1,0) (0,0,1)\nspace origin: (10000,10000,10000)\n"
        "encoding: raw\n\n");
    labels.write(QByteArray(64, 1));
    labels.close();
    QVERIFY(!v.window.openLabels(far));
    QVERIFY2(v.error.contains("does not overlap"), qPrintable(v.error));
    QVERIFY(!v.window.loadScene(folder.filePath("missing.json")));
    // A hand-edited scene whose camera is not a point: named, nothing changed.
    const QString badCamera = folder.filePath("bad_camera.json");
    QFile sceneFile(badCamera);
    QVERIFY(sceneFile.open(QIODevice::WriteOnly));
    sceneFile.write(
        QString(R"({"volumes": {"scalars": {"file": "%1"}}, "camera": {"position": [1, 2], "look_at": [0, 0, 0]}})")
            .arg(Data("ct_head_headsq.nrrd"))
            .toUtf8());
    sceneFile.close();
    v.error.clear();
    QVERIFY(!v.window.loadScene(badCamera));
    QVERIFY2(v.error.contains("bad_camera.json") && v.error.contains("position"), qPrintable(v.error));
    QVERIFY(v.window.scene().VolumePath().find("ct_head_cranium.nrrd") != std::string::npos);
    QVERIFY(RefineTo(v.window, 8));  // the head CT still renders
  }

  void aSavedSceneRendersTheSameInMmrtmRender() {
    Viewer v;
    QVERIFY(v.window.openVolume(Data("ct_head_headsq.nrrd")));
    QVERIFY(v.window.setPreset("ct-bone"));
    // A view of the user's own, not the one a reset gives: the scene keeps it.
    v.window.view()->Renderer()->GetActiveCamera()->Azimuth(35);
    v.window.view()->Renderer()->GetActiveCamera()->Elevation(-20);
    v.window.view()->Renderer()->ResetCameraClippingRange();
    v.window.view()->update();
    QVERIFY(RefineTo(v.window, 8));
    QTemporaryDir folder;
    const QString scene = folder.filePath("scene.json"), viewer = folder.filePath("viewer.pfm"),
                  rendered = folder.filePath("render.pfm");
    QVERIFY(v.window.saveScene(scene));
    QVERIFY(v.window.saveLinearImage(viewer));
    QProcess render;
    render.start(MMRTM_RENDER, {"--scene", scene, "--output", folder.filePath("render.png"), "--output-linear",
                                rendered, "--backend", "cpu"});
    QVERIFY(render.waitForFinished(120000));
    QVERIFY2(render.exitCode() == 0, render.readAllStandardError().constData());
    const mmrtm::RGBImage a = mmrtm::ReadPFM(viewer.toStdString()), b = mmrtm::ReadPFM(rendered.toStdString());
    QCOMPARE(a.width, b.width);
    QCOMPARE(a.height, b.height);
    size_t differing = 0;
    double lit = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) differing += a.pixels[i][c] != b.pixels[i][c];
      lit += a.pixels[i][1] > 0.01;
    }
    qInfo("viewer vs mmrtm-render: %zu of %zu values differ; %.0f lit pixels", differing, 3 * a.pixels.size(), lit);
    QVERIFY2(lit > 0.05 * a.pixels.size(), "an empty render");
    QCOMPARE(differing, size_t(0));
    // The scene loaded into another window: the same view, the same image.
    Viewer other;
    QVERIFY2(other.window.loadScene(scene), qPrintable(other.error));
    QVERIFY(RefineTo(other.window, 8));
    const QString reloaded = folder.filePath("reloaded.pfm");
    QVERIFY(other.window.saveLinearImage(reloaded));
    const mmrtm::RGBImage c = mmrtm::ReadPFM(reloaded.toStdString());
    QCOMPARE(c.pixels.size(), a.pixels.size());
    size_t changed = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
      for (int k = 0; k < 3; ++k) changed += a.pixels[i][k] != c.pixels[i][k];
    QCOMPARE(changed, size_t(0));
  }

  void closingTheWindowWhileItRefinesIsClean() {
    auto* window = new MainWindow;
    window->setErrorHandler([](const QString&) {});
    window->resize(1000, 640);
    window->show();
    QVERIFY(QTest::qWaitForWindowExposed(window));
    mmrtm::viewer::RenderSettings s = window->renderSettings()->settings();
    s.maximumSamples = 100000;  // it would refine for minutes
    window->scene().SetSettings(s);
    QVERIFY(window->openVolume(Data("ct_head_cranium.nrrd")));
    QVERIFY(RefineTo(*window, 2));
    QVERIFY(!window->scene().Mapper()->IsConverged());
    window->close();
    delete window;      // with refinement steps scheduled
    QTest::qWait(300);  // the event loop runs on: nothing refers to the window
  }

  void theDefaultDisplayIsDenoisedAndKeepsTheAccumulation() {
    QCOMPARE(MainWindow().renderSettings()->settings().denoising, 1);  // auto, the default
    Viewer v(1);
    QVERIFY(v.window.openVolume(Data("ct_head_cranium.nrrd")));
    vtkMultiMaterialVolumeMapper* m = v.window.scene().Mapper();
    QVERIFY(RefineTo(v.window, 8));
    if (QString::fromUtf8(m->GetDisplayStatus()).contains("not denoised"))
      QSKIP(m->GetDisplayStatus());  // no denoiser here (a build with sanitizers does not start it)
    // Auto at 8 samples: the denoised image, once its last denoise is drawn.
    QTRY_VERIFY_WITH_TIMEOUT(m->IsConverged() && v.window.statusLine()->text().contains("shown: denoised, 8 samples"),
                             30000);
    QVERIFY(m->IsDenoisedImageShown());
    const QImage denoised = View(v.window);
    // The unbiased image from the same accumulation: switching the display
    // adds no sample and starts nothing again.
    mmrtm::viewer::RenderSettings s = v.window.renderSettings()->settings();
    s.denoising = 0;
    v.window.renderSettings()->setSettings(s);
    v.window.scene().SetSettings(s);
    v.window.view()->update();
    QTRY_VERIFY_WITH_TIMEOUT(v.window.statusLine()->text().contains("shown: unbiased, 8 samples"), 30000);
    QCOMPARE(m->GetAccumulatedSamples(), 8);
    const QImage unbiased = View(v.window);
    // Noise: the mean difference between horizontal neighbours, lower in the
    // denoised view (measured 0.0022 against 0.0203; held to half).
    const auto roughness = [](const QImage& image) {
      double sum = 0;
      for (int y = 0; y < image.height(); ++y)
        for (int x = 1; x < image.width(); ++x)
          sum += std::abs(image.pixelColor(x, y).lightnessF() - image.pixelColor(x - 1, y).lightnessF());
      return sum / (image.height() * (image.width() - 1));
    };
    qInfo("neighbour difference: denoised %.4f, unbiased %.4f", roughness(denoised), roughness(unbiased));
    QVERIFY(roughness(denoised) < 0.5 * roughness(unbiased));
    QVERIFY(std::abs(Coverage(denoised) - Coverage(unbiased)) < 0.02);
  }

  void windowScreenshotMatchesTheBaseline() {
    Viewer v;
    QVERIFY(v.window.openVolume(Data("ct_head_cranium.nrrd")));
    QVERIFY(RefineTo(v.window, 8));
    // The mapper counts 8 samples once its background pass is done; the view
    // shows them at its next repaint, which then updates the status line. A
    // fixed wait can end before that repaint on a loaded machine.
    QTRY_VERIFY_WITH_TIMEOUT(v.window.statusLine()->text().contains("8 samples/pixel"), 30000);
    QTest::qWait(100);
    const QImage window = v.window.grab().toImage().convertToFormat(QImage::Format_RGB888);
    const QString temporary = QString(MMRTM_TEST_OUTPUT_DIR) + "/mmrtm-viewer-window.png";
    window.save(temporary);
    const QImage baseline = QImage(QString(MMRTM_DATA_DIR) + "/Baselines/Viewer/mmrtm-viewer-window.png")
                                .convertToFormat(QImage::Format_RGB888);
    QVERIFY2(!baseline.isNull(), "no baseline (the test wrote the window to Testing/Output)");
    QCOMPARE(window.size(), baseline.size());
    // The 3D view exactly (one seed, one sample count); the rest (fonts,
    // widget styles) at 1/8 of the size, within 6 %.
    const QRect view(v.window.view()->mapTo(&v.window, QPoint(0, 0)), v.window.view()->size());
    const double viewDifference = MeanDifference(window.copy(view), baseline.copy(view));
    const auto coarse = [](const QImage& i) {
      return i.scaled(i.size() / 8, Qt::IgnoreAspectRatio, Qt::SmoothTransformation);
    };
    const double windowDifference = MeanDifference(coarse(window), coarse(baseline));
    qInfo("view differs by %.4f, window (1/8 size) by %.4f; image in %s", viewDifference, windowDifference,
          qPrintable(temporary));
    QVERIFY(viewDifference < 0.01);
    QVERIFY(windowDifference < 0.06);
  }
};

int main(int argc, char** argv) {
  QSurfaceFormat::setDefaultFormat(mmrtm::viewer::VtkOpenGLWidget::DefaultFormat());
  QApplication app(argc, argv);
  TestMmrtmViewer test;
  return QTest::qExec(&test, argc, argv);
}

#include "TestMmrtmViewer.moc"
