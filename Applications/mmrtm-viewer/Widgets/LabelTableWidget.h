// The label table of a label map: per label its name, colour (a swatch;
// click for QColorDialog), whether it is visible, its opacity and its
// material kind (surface probability and roughness). Plain Qt.
#pragma once

#include <QColor>
#include <QString>
#include <QTableWidget>
#include <QVector>

namespace mmrtm::viewer {

struct LabelEntry {
  int id = 0;
  QString name;
  QColor color;
  bool visible = true;
  double opacity = 1.0;              // 0..1: the fraction of the label material's density
  double surfaceProbability = 0.75;  // 0: volume scattering only, 1: a surface
  double roughness = 0.45;
};

class LabelTableWidget : public QTableWidget {
  Q_OBJECT

 public:
  enum Column { Id, Name, Color, Visible, Opacity, Surface, Roughness, ColumnCount };
  explicit LabelTableWidget(QWidget* parent = nullptr);

  void setLabels(const QVector<LabelEntry>& labels);
  const QVector<LabelEntry>& labels() const { return labels_; }
  // Edits a label as the user would (and emits labelEdited); tests and the
  // viewer's menus use it.
  void setLabel(int row, const LabelEntry& entry);

 signals:
  void labelEdited(int row);

 private:
  void fillRow(int row);
  QVector<LabelEntry> labels_;
  bool filling_ = false;
};

}  // namespace mmrtm::viewer
