// mmrtm-viewer: a desktop viewer for the MM-RTM path tracer. Opens a CT or
// MRI (a file or a DICOM folder), its label map and table, lets the user
// shape transfer functions and label materials, and shows the image
// converging (Documentation/viewer.md).
#include <QApplication>
#include <QCommandLineParser>
#include <QSurfaceFormat>
#include <QTimer>

#include <cstdio>

#include "MainWindow.h"
#include "VtkOpenGLWidget.h"
#include "mmrtmVolumeLoader.h"
#include "vtkMultiMaterialVolumeMapper.h"

int main(int argc, char* argv[]) {
  // VTK's OpenGL format must be Qt's default before the application exists.
  QSurfaceFormat::setDefaultFormat(mmrtm::viewer::VtkOpenGLWidget::DefaultFormat());
  QApplication app(argc, argv);
  QApplication::setApplicationName("mmrtm-viewer");
  QCommandLineParser parser;
  parser.setApplicationDescription(
      "Physically based volume rendering (MM-RTM) of a CT or MRI. FILE is a volume (NRRD, NIfTI, MetaImage, VTK, "
      "InVesalius .inv3), a DICOM folder or a saved scene (.json); default: the head CT of Debian's "
      "invesalius-examples.");
  parser.addHelpOption();
  parser.addPositionalArgument("FILE", "volume, DICOM folder or scene to open");
  parser.addOption({"labels", "label map of the volume", "FILE"});
  parser.addOption({"label-table", "names and colours of the labels (id name [r g b [a]], or .ctbl)", "FILE"});
  parser.addOption({"preset", "material preset (Data/presets: ct-bone, ct-soft-tissue, ct-organs, mri, ...)", "NAME"});
  parser.addOption({"screenshot", "render until --samples samples per pixel, save the window as PNG, quit", "PNG"});
  parser.addOption({"samples", "samples per pixel for --screenshot (default 32)", "N", "32"});
  parser.addOption({"window", "with --screenshot: the whole window, not only the view"});
  parser.addOption({"tab", "with --screenshot: the editor tab to show (materials, labels, render)", "NAME"});
  parser.process(app);

  mmrtm::viewer::MainWindow window;
  if (parser.isSet("screenshot"))  // headless use: errors to stderr, not dialogs
    window.setErrorHandler([](const QString& m) { std::fprintf(stderr, "mmrtm-viewer: %s\n", qPrintable(m)); });
  window.show();
  QString input = parser.positionalArguments().value(0);
  if (input.isEmpty()) input = QString::fromStdString(mmrtm::DefaultVolumePath());
  bool ok = true;
  if (parser.isSet("preset")) ok = window.setPreset(parser.value("preset")) && ok;
  if (input.endsWith(".json", Qt::CaseInsensitive))
    ok = window.loadScene(input) && ok;
  else
    ok = window.openVolume(input) && ok;
  if (parser.isSet("labels")) ok = window.openLabels(parser.value("labels")) && ok;
  if (parser.isSet("label-table")) ok = window.openLabelTable(parser.value("label-table")) && ok;

  if (parser.isSet("screenshot")) {
    if (!ok) return 1;
    if (parser.isSet("tab")) window.showEditor(parser.value("tab"));
    const int samples = parser.value("samples").toInt();
    QObject::connect(window.view(), &mmrtm::viewer::VtkOpenGLWidget::rendered, &app, [&] {
      vtkMultiMaterialVolumeMapper* mapper = window.scene().Mapper();
      if (mapper->GetAccumulatedSamples() < samples && !mapper->IsConverged()) return;
      // After this paint has finished: grabbing renders the widget again.
      QTimer::singleShot(0, &app, [&] {
        const QString path = parser.value("screenshot");
        const bool saved = parser.isSet("window") ? window.grab().save(path, "PNG") : window.saveImage(path);
        std::fprintf(stderr, "%s: %d samples per pixel\n", qPrintable(parser.value("screenshot")),
                     window.scene().Mapper()->GetAccumulatedSamples());
        app.exit(saved ? 0 : 1);
      });
    });
  }
  return app.exec();
}
