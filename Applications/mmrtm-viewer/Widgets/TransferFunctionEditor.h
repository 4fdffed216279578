// A transfer-function editor: the volume's histogram (log scale) behind a
// piecewise-linear curve (a material's density over the scalar value, 0 to
// 1) whose points are dragged, added (click on empty space) and deleted
// (right click, or Delete on the selected point); below it, a colour
// gradient (the material's albedo) whose stops are dragged, added (double
// click on the bar), recoloured (double click on a stop: QColorDialog) and
// deleted (right click). Plain Qt: it knows nothing of VTK or the tracer.
#pragma once

#include <QColor>
#include <QPointF>
#include <QVector>
#include <QWidget>

namespace mmrtm::viewer {

struct ColorStop {
  double x = 0;
  QColor color;
};

class TransferFunctionEditor : public QWidget {
  Q_OBJECT

 public:
  explicit TransferFunctionEditor(QWidget* parent = nullptr);

  // The scalar range shown (the volume's), and its histogram (counts per
  // equal-width bin over the range; drawn on a log scale).
  void setRange(double low, double high);
  void setHistogram(const QVector<double>& counts);

  // The curve: points in ascending x, y in [0, 1]; at least one.
  void setPoints(const QVector<QPointF>& points);
  const QVector<QPointF>& points() const { return points_; }
  // The gradient: stops in ascending x; at least one.
  void setStops(const QVector<ColorStop>& stops);
  const QVector<ColorStop>& stops() const { return stops_; }

  // The selected curve point (-1: none) and numeric entry for it: x is
  // clamped between its neighbours, y to [0, 1].
  int selectedPoint() const { return selectedPoint_; }
  void selectPoint(int index);
  void setSelectedPoint(double x, double y);

  // Widget coordinates of a curve point and of a gradient stop (tests).
  QPoint pointPosition(int index) const;
  QPoint stopPosition(int index) const;
  QSize sizeHint() const override { return {420, 220}; }

 signals:
  // The curve or the gradient changed: `interactive` while the mouse drags,
  // false when an edit is complete (release, add, delete, numeric entry).
  void edited(bool interactive);
  void selectionChanged(int point);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;

 private:
  QRectF curveArea() const;
  QRectF gradientArea() const;
  double toX(double value) const;
  double fromX(double pixel) const;
  double toY(double opacity) const;
  double fromY(double pixel) const;
  int pointAt(const QPointF& pos) const;
  int stopAt(const QPointF& pos) const;
  QColor colorAt(double x) const;
  void movePoint(int index, double x, double y);

  double low_ = 0, high_ = 1;
  QVector<double> histogram_;
  QVector<QPointF> points_{{0, 0}, {1, 1}};
  QVector<ColorStop> stops_{{0, Qt::white}};
  int selectedPoint_ = -1;
  int draggedPoint_ = -1, draggedStop_ = -1;
};

}  // namespace mmrtm::viewer
