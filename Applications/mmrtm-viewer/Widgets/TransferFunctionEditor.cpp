#include "TransferFunctionEditor.h"

#include <QColorDialog>
#include <QKeyEvent>
#include <QLinearGradient>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cmath>

namespace mmrtm::viewer {
namespace {
constexpr double kMargin = 8;           // pixels around the plot
constexpr double kGradientHeight = 22;  // the colour bar under the curve
constexpr double kGap = 6;              // between the curve and the bar
constexpr double kPickRadius = 7;       // how close a click must be to a handle
}  // namespace

TransferFunctionEditor::TransferFunctionEditor(QWidget* parent) : QWidget(parent) {
  setFocusPolicy(Qt::StrongFocus);
  setMinimumSize(240, 140);
}

void TransferFunctionEditor::setRange(double low, double high) {
  low_ = low;
  high_ = high > low ? high : low + 1;
  update();
}

void TransferFunctionEditor::setHistogram(const QVector<double>& counts) {
  histogram_ = counts;
  update();
}

void TransferFunctionEditor::setPoints(const QVector<QPointF>& points) {
  points_ = points.isEmpty() ? QVector<QPointF>{{low_, 0}} : points;
  std::sort(points_.begin(), points_.end(), [](const QPointF& a, const QPointF& b) { return a.x() < b.x(); });
  if (selectedPoint_ >= points_.size()) selectPoint(-1);
  update();
}

void TransferFunctionEditor::setStops(const QVector<ColorStop>& stops) {
  stops_ = stops.isEmpty() ? QVector<ColorStop>{{low_, Qt::white}} : stops;
  std::sort(stops_.begin(), stops_.end(), [](const ColorStop& a, const ColorStop& b) { return a.x < b.x; });
  update();
}

void TransferFunctionEditor::selectPoint(int index) {
  if (index == selectedPoint_) return;
  selectedPoint_ = index;
  update();
  emit selectionChanged(index);
}

void TransferFunctionEditor::setSelectedPoint(double x, double y) {
  if (selectedPoint_ < 0) return;
  movePoint(selectedPoint_, x, y);
  emit edited(false);
}

QRectF TransferFunctionEditor::curveArea() const {
  return QRectF(kMargin, kMargin, width() - 2 * kMargin, height() - 2 * kMargin - kGradientHeight - kGap);
}

QRectF TransferFunctionEditor::gradientArea() const {
  const QRectF c = curveArea();
  return QRectF(c.left(), c.bottom() + kGap, c.width(), kGradientHeight);
}

double TransferFunctionEditor::toX(double value) const {
  const QRectF c = curveArea();
  return c.left() + (value - low_) / (high_ - low_) * c.width();
}

double TransferFunctionEditor::fromX(double pixel) const {
  const QRectF c = curveArea();
  return low_ + (pixel - c.left()) / c.width() * (high_ - low_);
}

double TransferFunctionEditor::toY(double opacity) const {
  const QRectF c = curveArea();
  return c.bottom() - opacity * c.height();
}

double TransferFunctionEditor::fromY(double pixel) const {
  const QRectF c = curveArea();
  return std::clamp((c.bottom() - pixel) / c.height(), 0.0, 1.0);
}

QPoint TransferFunctionEditor::pointPosition(int index) const {
  return QPointF(toX(points_[index].x()), toY(points_[index].y())).toPoint();
}

QPoint TransferFunctionEditor::stopPosition(int index) const {
  return QPointF(toX(stops_[index].x), gradientArea().center().y()).toPoint();
}

int TransferFunctionEditor::pointAt(const QPointF& pos) const {
  for (int i = 0; i < points_.size(); ++i)
    if (QLineF(pos, QPointF(toX(points_[i].x()), toY(points_[i].y()))).length() <= kPickRadius) return i;
  return -1;
}

int TransferFunctionEditor::stopAt(const QPointF& pos) const {
  if (!gradientArea().adjusted(-kPickRadius, 0, kPickRadius, 0).contains(pos)) return -1;
  for (int i = 0; i < stops_.size(); ++i)
    if (std::abs(pos.x() - toX(stops_[i].x)) <= kPickRadius) return i;
  return -1;
}

QColor TransferFunctionEditor::colorAt(double x) const {
  if (x <= stops_.front().x) return stops_.front().color;
  if (x >= stops_.back().x) return stops_.back().color;
  for (int i = 1; i < stops_.size(); ++i)
    if (x <= stops_[i].x) {
      const double t = (x - stops_[i - 1].x) / std::max(1e-12, stops_[i].x - stops_[i - 1].x);
      const QColor a = stops_[i - 1].color, b = stops_[i].color;
      return QColor::fromRgbF(a.redF() + t * (b.redF() - a.redF()), a.greenF() + t * (b.greenF() - a.greenF()),
                              a.blueF() + t * (b.blueF() - a.blueF()));
    }
  return stops_.back().color;
}

// A point stays between its neighbours, so the curve stays a function.
void TransferFunctionEditor::movePoint(int index, double x, double y) {
  const double lo = index > 0 ? points_[index - 1].x() : low_;
  const double hi = index + 1 < points_.size() ? points_[index + 1].x() : high_;
  points_[index] = QPointF(std::clamp(x, lo, hi), std::clamp(y, 0.0, 1.0));
  update();
}

void TransferFunctionEditor::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  p.fillRect(rect(), palette().base());
  const QRectF c = curveArea();
  p.fillRect(c, QColor(30, 30, 34));

  // Histogram, log scale.
  if (!histogram_.isEmpty()) {
    const double peak = std::log1p(*std::max_element(histogram_.begin(), histogram_.end()));
    const double w = c.width() / histogram_.size();
    p.setPen(Qt::NoPen);
    p.setBrush(QColor(90, 90, 100));
    for (int i = 0; i < histogram_.size(); ++i) {
      const double h = peak > 0 ? std::log1p(histogram_[i]) / peak * c.height() : 0;
      p.drawRect(QRectF(c.left() + i * w, c.bottom() - h, w + 0.5, h));
    }
  }

  // The curve, filled with the gradient's colours.
  QPainterPath curve;
  curve.moveTo(c.left(), toY(points_.front().y()));
  for (const QPointF& q : points_) curve.lineTo(toX(q.x()), toY(q.y()));
  curve.lineTo(c.right(), toY(points_.back().y()));
  QPainterPath area = curve;
  area.lineTo(c.right(), c.bottom());
  area.lineTo(c.left(), c.bottom());
  area.closeSubpath();
  QLinearGradient fill(c.left(), 0, c.right(), 0);
  for (int i = 0; i <= 32; ++i) {
    QColor col = colorAt(low_ + (high_ - low_) * i / 32.0);
    col.setAlpha(110);
    fill.setColorAt(i / 32.0, col);
  }
  p.setPen(Qt::NoPen);
  p.setBrush(fill);
  p.drawPath(area);
  p.setPen(QPen(QColor(240, 240, 240), 1.5));
  p.setBrush(Qt::NoBrush);
  p.drawPath(curve);
  for (int i = 0; i < points_.size(); ++i) {
    p.setBrush(i == selectedPoint_ ? QColor(255, 200, 60) : QColor(230, 230, 230));
    p.setPen(QPen(Qt::black, 1));
    p.drawEllipse(QPointF(toX(points_[i].x()), toY(points_[i].y())), 4.5, 4.5);
  }

  // The colour bar and its stops.
  const QRectF g = gradientArea();
  QLinearGradient bar(g.left(), 0, g.right(), 0);
  for (int i = 0; i <= 64; ++i) bar.setColorAt(i / 64.0, colorAt(low_ + (high_ - low_) * i / 64.0));
  p.fillRect(g, bar);
  p.setPen(QPen(Qt::black, 1));
  for (const ColorStop& s : stops_) {
    const double x = toX(s.x);
    QPolygonF marker({QPointF(x, g.top() + 2), QPointF(x - 5, g.bottom()), QPointF(x + 5, g.bottom())});
    p.setBrush(s.color);
    p.drawPolygon(marker);
  }
}

void TransferFunctionEditor::mousePressEvent(QMouseEvent* event) {
  const QPointF pos = event->position();
  if (const int stop = stopAt(pos); stop >= 0) {
    if (event->button() == Qt::RightButton && stops_.size() > 1) {
      stops_.remove(stop);
      update();
      emit edited(false);
    } else if (event->button() == Qt::LeftButton) {
      draggedStop_ = stop;
    }
    return;
  }
  if (!curveArea().adjusted(-kPickRadius, -kPickRadius, kPickRadius, kPickRadius).contains(pos)) return;
  int point = pointAt(pos);
  if (event->button() == Qt::RightButton) {
    if (point >= 0 && points_.size() > 1) {
      points_.remove(point);
      selectPoint(-1);
      update();
      emit edited(false);
    }
    return;
  }
  if (event->button() != Qt::LeftButton) return;
  if (point < 0) {  // a new point on empty space, where the click is
    const QPointF added(std::clamp(fromX(pos.x()), low_, high_), fromY(pos.y()));
    point = int(std::upper_bound(points_.begin(), points_.end(), added,
                                 [](const QPointF& a, const QPointF& b) { return a.x() < b.x(); }) -
                points_.begin());
    points_.insert(point, added);
    update();
    emit edited(true);
  }
  selectPoint(point);
  draggedPoint_ = point;
}

void TransferFunctionEditor::mouseMoveEvent(QMouseEvent* event) {
  const QPointF pos = event->position();
  if (draggedPoint_ >= 0) {
    movePoint(draggedPoint_, fromX(pos.x()), fromY(pos.y()));
    emit edited(true);
  } else if (draggedStop_ >= 0) {
    const double lo = draggedStop_ > 0 ? stops_[draggedStop_ - 1].x : low_;
    const double hi = draggedStop_ + 1 < stops_.size() ? stops_[draggedStop_ + 1].x : high_;
    stops_[draggedStop_].x = std::clamp(fromX(pos.x()), lo, hi);
    update();
    emit edited(true);
  }
}

void TransferFunctionEditor::mouseReleaseEvent(QMouseEvent*) {
  if (draggedPoint_ >= 0 || draggedStop_ >= 0) {
    draggedPoint_ = draggedStop_ = -1;
    emit edited(false);
  }
}

void TransferFunctionEditor::mouseDoubleClickEvent(QMouseEvent* event) {
  const QPointF pos = event->position();
  if (!gradientArea().contains(pos)) return;
  int stop = stopAt(pos);
  if (stop < 0) {  // a new stop, in the colour the bar has there
    const double x = std::clamp(fromX(pos.x()), low_, high_);
    const ColorStop added{x, colorAt(x)};
    stop = int(std::upper_bound(stops_.begin(), stops_.end(), added,
                                [](const ColorStop& a, const ColorStop& b) { return a.x < b.x; }) -
               stops_.begin());
    stops_.insert(stop, added);
  }
  const QColor chosen = QColorDialog::getColor(stops_[stop].color, this, tr("Colour at %1").arg(stops_[stop].x));
  if (chosen.isValid()) stops_[stop].color = chosen;
  draggedStop_ = -1;
  update();
  emit edited(false);
}

void TransferFunctionEditor::keyPressEvent(QKeyEvent* event) {
  if ((event->key() == Qt::Key_Delete || event->key() == Qt::Key_Backspace) && selectedPoint_ >= 0 &&
      points_.size() > 1) {
    points_.remove(selectedPoint_);
    selectPoint(-1);
    update();
    emit edited(false);
    return;
  }
  QWidget::keyPressEvent(event);
}

}  // namespace mmrtm::viewer
