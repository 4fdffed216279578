// Benchmark (not a test) of the viewer's responsiveness, in the window a
// user has (1280 x 800, the head CT, ct-bone): how late the event loop
// serves a 10 ms timer while the image refines (the delay a click or a key
// waits), and, after a transfer-function point is dragged and released, the
// time to the first full-resolution image and to 16 samples per pixel.
//
//   xvfb-run -a -s "-screen 0 1280x1024x24" build/bin/mmrtm-bench-viewer [VOLUME]
#include <QApplication>
#include <QElapsedTimer>
#include <QSurfaceFormat>
#include <QTimer>
#include <QtTest>

#include <algorithm>
#include <cstdio>
#include <vector>

#include <vtkGenericOpenGLRenderWindow.h>

#include "MainWindow.h"
#include "TransferFunctionEditor.h"
#include "VtkOpenGLWidget.h"
#include "vtkMultiMaterialVolumeMapper.h"

namespace {
double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * (v.size() - 1) + 0.5))];
}
}  // namespace

int main(int argc, char** argv) {
  QSurfaceFormat::setDefaultFormat(mmrtm::viewer::VtkOpenGLWidget::DefaultFormat());
  QApplication app(argc, argv);
  const QString volume = argc > 1 ? argv[1] : QString(MMRTM_SHARED_DATA_DIR) + "/ct_head_cranium.nrrd";
  mmrtm::viewer::MainWindow window;
  window.setErrorHandler([](const QString& m) { std::fprintf(stderr, "error: %s\n", qPrintable(m)); });
  window.resize(1280, 800);
  window.show();
  if (!QTest::qWaitForWindowExposed(&window) || !window.openVolume(volume)) return 1;
  vtkMultiMaterialVolumeMapper* mapper = window.scene().Mapper();
  const int* size = window.view()->RenderWindow()->GetSize();

  // 1. Event-loop delay while refining: a 10 ms timer's lateness for 8 s.
  std::vector<double> late;
  QElapsedTimer clock;
  clock.start();
  qint64 expected = 10;
  QTimer tick;
  QObject::connect(&tick, &QTimer::timeout, [&] {
    late.push_back(std::max<qint64>(0, clock.elapsed() - expected));
    expected = clock.elapsed() + 10;
  });
  tick.start(10);
  QTest::qWait(8000);
  tick.stop();
  std::printf("view %d x %d, %d samples per pixel after 8 s; render step %.0f ms\n", size[0], size[1],
              mapper->GetAccumulatedSamples(), window.view()->LastRenderMilliseconds());
  std::printf("event-loop delay while refining: median %.0f ms, 95th percentile %.0f ms, max %.0f ms (%zu ticks)\n",
              Percentile(late, 0.5), Percentile(late, 0.95), Percentile(late, 1.0), late.size());

  // 2. Drag the middle point of the density curve, release, time the refinement.
  mmrtm::viewer::TransferFunctionEditor* editor = window.transferFunctionEditor();
  const QPoint from = editor->pointPosition(std::min<int>(1, editor->points().size() - 1));
  QTest::mousePress(editor, Qt::LeftButton, {}, from);
  for (int i = 1; i <= 10; ++i) {
    QTest::mouseMove(editor, from + QPoint(3 * i, 0));
    QTest::qWait(30);
  }
  QTest::mouseRelease(editor, Qt::LeftButton, {}, from + QPoint(30, 0));
  QElapsedTimer sinceRelease;
  sinceRelease.start();
  if (!QTest::qWaitFor([&] { return mapper->GetAccumulatedSamples() >= 1; }, 60000)) return 1;
  const qint64 first = sinceRelease.elapsed();
  if (!QTest::qWaitFor([&] { return mapper->GetAccumulatedSamples() >= 16; }, 300000)) return 1;
  std::printf(
      "after releasing a TF point: first full-resolution image %lld ms, 16 samples per pixel %lld ms; "
      "last refit %.1f ms\n",
      first, sinceRelease.elapsed(), mapper->GetLastRefitSeconds() * 1000);
  return 0;
}
