// A QOpenGLWidget that shows a VTK renderer: vtkGenericOpenGLRenderWindow
// renders in Qt's OpenGL context and its image is blitted into the widget's
// framebuffer. Debian's VTK 9.1 supports Qt 5 only (QVTKOpenGLNativeWidget),
// so this is the few lines of it a Qt 6 program needs; see
// Documentation/viewer.md for the facts it relies on. The mouse turns,
// pans and zooms the camera (trackball); while a button is held the render
// window asks for an interactive frame rate, which makes the path tracer
// draw its quick preview, and releasing it lets the image refine again.
#pragma once

#include <QOpenGLWidget>
#include <QPoint>
#include <vtkNew.h>

class vtkGenericOpenGLRenderWindow;
class vtkRenderer;

namespace mmrtm::viewer {

class VtkOpenGLWidget : public QOpenGLWidget {
  Q_OBJECT

 public:
  explicit VtkOpenGLWidget(QWidget* parent = nullptr);
  ~VtkOpenGLWidget() override;

  // The OpenGL format VTK needs (as QVTKOpenGLNativeWidget::defaultFormat):
  // set as Qt's default before the QApplication is made.
  static QSurfaceFormat DefaultFormat();

  vtkRenderer* Renderer() { return renderer_; }
  vtkGenericOpenGLRenderWindow* RenderWindow() { return window_; }
  // Whether a mouse button is held (the camera is moving).
  bool Interacting() const { return button_ != Qt::NoButton; }
  // Milliseconds the last paint spent in VTK's Render().
  double LastRenderMilliseconds() const { return lastRenderMs_; }

  // Camera: reset to the visible props, and turn about the focal point.
  void ResetCamera();
  void Rotate(double azimuthDegrees, double elevationDegrees);

 signals:
  // After each paint, when the image was rendered.
  void rendered();
  // The camera moved (by the mouse or the keyboard).
  void cameraChanged();

 protected:
  void initializeGL() override;
  void resizeGL(int width, int height) override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;

 private:
  void SetInteractive(bool interactive);

  vtkNew<vtkGenericOpenGLRenderWindow> window_;
  vtkNew<vtkRenderer> renderer_;
  Qt::MouseButton button_ = Qt::NoButton;
  QPoint last_;
  double lastRenderMs_ = 0;
  unsigned long makeCurrentObserver_ = 0, isCurrentObserver_ = 0;
};

}  // namespace mmrtm::viewer
