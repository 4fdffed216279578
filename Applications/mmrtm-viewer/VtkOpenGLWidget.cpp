#include "VtkOpenGLWidget.h"

#include <QElapsedTimer>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFunctions>
#include <QSurfaceFormat>
#include <QWheelEvent>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkRenderer.h>

namespace mmrtm::viewer {
namespace {
// The frame rates the render window asks for: while the camera moves (as
// vtkRenderWindowInteractor's default), and when it stands still.
constexpr double kInteractiveRate = 15.0;
constexpr double kStillRate = 0.0001;
}  // namespace

VtkOpenGLWidget::VtkOpenGLWidget(QWidget* parent) : QOpenGLWidget(parent) {
  setFocusPolicy(Qt::StrongFocus);
  setMinimumSize(200, 200);
  window_->AddRenderer(renderer_);
  window_->SetDesiredUpdateRate(kStillRate);
  renderer_->SetBackground(0.08, 0.08, 0.1);
  // VTK asks to make the context current and whether it is; Qt's context is
  // made current directly (QOpenGLWidget::makeCurrent would rebind Qt's
  // framebuffer behind VTK's back and blank the image).
  auto makeCurrent = vtkSmartPointer<vtkCallbackCommand>::New();
  makeCurrent->SetClientData(this);
  makeCurrent->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    auto* w = static_cast<VtkOpenGLWidget*>(self);
    if (QOpenGLContext* c = w->context(); c && QOpenGLContext::currentContext() != c) c->makeCurrent(c->surface());
  });
  makeCurrentObserver_ = window_->AddObserver(vtkCommand::WindowMakeCurrentEvent, makeCurrent);
  auto isCurrent = vtkSmartPointer<vtkCallbackCommand>::New();
  isCurrent->SetClientData(this);
  isCurrent->SetCallback([](vtkObject*, unsigned long, void* self, void* call) {
    auto* w = static_cast<VtkOpenGLWidget*>(self);
    *static_cast<bool*>(call) = w->context() && QOpenGLContext::currentContext() == w->context();
  });
  isCurrentObserver_ = window_->AddObserver(vtkCommand::WindowIsCurrentEvent, isCurrent);
}

VtkOpenGLWidget::~VtkOpenGLWidget() {
  // Graphics resources go with the context they were made in.
  makeCurrent();
  window_->Finalize();
  doneCurrent();
  window_->RemoveObserver(makeCurrentObserver_);
  window_->RemoveObserver(isCurrentObserver_);
}

QSurfaceFormat VtkOpenGLWidget::DefaultFormat() {
  QSurfaceFormat format;
  format.setRenderableType(QSurfaceFormat::OpenGL);
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setRedBufferSize(8);
  format.setGreenBufferSize(8);
  format.setBlueBufferSize(8);
  format.setAlphaBufferSize(8);
  format.setDepthBufferSize(8);
  format.setStencilBufferSize(0);
  format.setSamples(0);
  format.setSwapBehavior(QSurfaceFormat::DoubleBuffer);
  return format;
}

void VtkOpenGLWidget::initializeGL() {
  window_->SetOwnContext(false);
  window_->SetReadyForRendering(true);
  window_->SetFrameBlitModeToNoBlit();  // the widget blits, into Qt's framebuffer
  const qreal ratio = devicePixelRatioF();
  window_->SetSize(int(width() * ratio), int(height() * ratio));
  window_->InitializeFromCurrentContext();
}

void VtkOpenGLWidget::resizeGL(int width, int height) {
  const qreal ratio = devicePixelRatioF();
  window_->SetSize(int(width * ratio), int(height * ratio));
}

void VtkOpenGLWidget::paintGL() {
  vtkOpenGLState* state = window_->GetState();
  state->Reset();  // Qt changed the OpenGL state since VTK last looked
  state->Push();
  QElapsedTimer timer;
  timer.start();
  window_->Render();
  lastRenderMs_ = timer.nsecsElapsed() / 1e6;
  // VTK's image into the widget's framebuffer (its id changes on resize).
  const int* size = window_->GetSize();
  state->PushDrawFramebufferBinding();
  QOpenGLFunctions* gl = context()->functions();
  gl->glBindFramebuffer(GL_FRAMEBUFFER, defaultFramebufferObject());
  window_->BlitDisplayFramebuffer(0, 0, 0, size[0], size[1], 0, 0, size[0], size[1], GL_COLOR_BUFFER_BIT, GL_NEAREST);
  // Opaque: Qt composes the widget with its alpha.
  state->vtkglColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_TRUE);
  state->vtkglClearColor(0, 0, 0, 1);
  state->vtkglClear(GL_COLOR_BUFFER_BIT);
  state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  state->PopDrawFramebufferBinding();
  state->Pop();
  emit rendered();
}

void VtkOpenGLWidget::SetInteractive(bool interactive) {
  window_->SetDesiredUpdateRate(interactive ? kInteractiveRate : kStillRate);
}

// The anterior view (world is LPS: from -y, superior up), fitted to what is
// visible, as mmrtm-render's default camera.
void VtkOpenGLWidget::ResetCamera() {
  double bounds[6];
  renderer_->ComputeVisiblePropBounds(bounds);
  if (bounds[0] <= bounds[1]) {
    const double centre[3] = {(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2};
    vtkCamera* camera = renderer_->GetActiveCamera();
    camera->SetFocalPoint(centre);
    camera->SetPosition(centre[0], centre[1] - 1.0, centre[2]);
    camera->SetViewUp(0, 0, 1);
  }
  renderer_->ResetCamera();
  emit cameraChanged();
  update();
}

void VtkOpenGLWidget::Rotate(double azimuthDegrees, double elevationDegrees) {
  vtkCamera* camera = renderer_->GetActiveCamera();
  camera->Azimuth(azimuthDegrees);
  camera->Elevation(elevationDegrees);
  camera->OrthogonalizeViewUp();
  renderer_->ResetCameraClippingRange();
  emit cameraChanged();
  update();
}

void VtkOpenGLWidget::mousePressEvent(QMouseEvent* event) {
  button_ = event->button();
  last_ = event->position().toPoint();
  SetInteractive(true);
}

// Left: rotate (trackball), middle or shift+left: pan, right: zoom.
void VtkOpenGLWidget::mouseMoveEvent(QMouseEvent* event) {
  if (button_ == Qt::NoButton) return;
  const QPoint pos = event->position().toPoint();
  const QPoint d = pos - last_;
  last_ = pos;
  vtkCamera* camera = renderer_->GetActiveCamera();
  if (button_ == Qt::LeftButton && !(event->modifiers() & Qt::ShiftModifier)) {
    Rotate(-200.0 * d.x() / width(), 200.0 * d.y() / height());
    return;
  }
  if (button_ == Qt::RightButton) {
    camera->Dolly(std::pow(1.01, -d.y()));
  } else {  // pan: move focal point and position along the view plane
    double focal[3], position[3], up[3], right[3];
    camera->GetFocalPoint(focal);
    camera->GetPosition(position);
    camera->GetViewUp(up);
    const double* normal = camera->GetViewPlaneNormal();
    right[0] = up[1] * normal[2] - up[2] * normal[1];
    right[1] = up[2] * normal[0] - up[0] * normal[2];
    right[2] = up[0] * normal[1] - up[1] * normal[0];
    const double scale = 2.0 * camera->GetDistance() * std::tan(camera->GetViewAngle() * M_PI / 360.0) / height();
    for (int i = 0; i < 3; ++i) {
      const double shift = scale * (d.x() * right[i] + d.y() * up[i]);
      focal[i] += shift;
      position[i] += shift;
    }
    camera->SetFocalPoint(focal);
    camera->SetPosition(position);
  }
  renderer_->ResetCameraClippingRange();
  emit cameraChanged();
  update();
}

void VtkOpenGLWidget::mouseReleaseEvent(QMouseEvent*) {
  button_ = Qt::NoButton;
  SetInteractive(false);
  update();  // the full-resolution image starts again
}

void VtkOpenGLWidget::wheelEvent(QWheelEvent* event) {
  renderer_->GetActiveCamera()->Dolly(std::pow(1.1, event->angleDelta().y() / 120.0));
  renderer_->ResetCameraClippingRange();
  emit cameraChanged();
  update();
}

// Arrows turn the camera, +/- zoom, R resets it.
void VtkOpenGLWidget::keyPressEvent(QKeyEvent* event) {
  switch (event->key()) {
    case Qt::Key_Left:
      Rotate(-10, 0);
      break;
    case Qt::Key_Right:
      Rotate(10, 0);
      break;
    case Qt::Key_Up:
      Rotate(0, 10);
      break;
    case Qt::Key_Down:
      Rotate(0, -10);
      break;
    case Qt::Key_Plus:
    case Qt::Key_Equal:
      renderer_->GetActiveCamera()->Dolly(1.2);
      emit cameraChanged();
      update();
      break;
    case Qt::Key_Minus:
      renderer_->GetActiveCamera()->Dolly(1 / 1.2);
      emit cameraChanged();
      update();
      break;
    case Qt::Key_R:
      ResetCamera();
      break;
    default:
      QOpenGLWidget::keyPressEvent(event);
  }
}

}  // namespace mmrtm::viewer
