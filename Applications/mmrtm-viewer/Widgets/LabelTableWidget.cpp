#include "LabelTableWidget.h"

#include <QCheckBox>
#include <QColorDialog>
#include <QDoubleSpinBox>
#include <QHeaderView>
#include <QPushButton>

namespace mmrtm::viewer {
namespace {
QDoubleSpinBox* UnitSpinBox(double value) {
  auto* box = new QDoubleSpinBox;
  box->setRange(0.0, 1.0);
  box->setSingleStep(0.05);
  box->setDecimals(2);
  box->setValue(value);
  box->setFrame(false);
  return box;
}
}  // namespace

LabelTableWidget::LabelTableWidget(QWidget* parent) : QTableWidget(parent) {
  setColumnCount(ColumnCount);
  setHorizontalHeaderLabels(
      {tr("Label"), tr("Name"), tr("Colour"), tr("Visible"), tr("Opacity"), tr("Surface"), tr("Roughness")});
  verticalHeader()->setVisible(false);
  verticalHeader()->setDefaultSectionSize(24);
  horizontalHeader()->setSectionResizeMode(QHeaderView::Fixed);
  horizontalHeader()->setSectionResizeMode(Name, QHeaderView::Stretch);
  for (const auto& [column, width] :
       {std::pair{Id, 40}, {Color, 44}, {Visible, 48}, {Opacity, 58}, {Surface, 58}, {Roughness, 64}})
    setColumnWidth(column, width);
  setSelectionBehavior(QAbstractItemView::SelectRows);
  setEditTriggers(QAbstractItemView::NoEditTriggers);
}

void LabelTableWidget::setLabels(const QVector<LabelEntry>& labels) {
  filling_ = true;
  labels_ = labels;
  setRowCount(labels_.size());
  for (int row = 0; row < labels_.size(); ++row) fillRow(row);
  filling_ = false;
}

void LabelTableWidget::setLabel(int row, const LabelEntry& entry) {
  labels_[row] = entry;
  filling_ = true;
  fillRow(row);
  filling_ = false;
  emit labelEdited(row);
}

void LabelTableWidget::fillRow(int row) {
  const LabelEntry& e = labels_[row];
  setItem(row, Id, new QTableWidgetItem(QString::number(e.id)));
  setItem(row, Name, new QTableWidgetItem(e.name));
  auto* swatch = new QPushButton;
  swatch->setToolTip(tr("Colour of %1: click to change").arg(e.name));
  swatch->setStyleSheet(QString("background-color: %1; border: 1px solid #404040; margin: 3px").arg(e.color.name()));
  connect(swatch, &QPushButton::clicked, this, [this, row] {
    const QColor chosen = QColorDialog::getColor(labels_[row].color, this, labels_[row].name);
    if (!chosen.isValid()) return;
    LabelEntry edited = labels_[row];
    edited.color = chosen;
    setLabel(row, edited);
  });
  setCellWidget(row, Color, swatch);
  auto* visible = new QCheckBox;
  visible->setChecked(e.visible);
  connect(visible, &QCheckBox::toggled, this, [this, row](bool on) {
    if (filling_) return;
    labels_[row].visible = on;
    emit labelEdited(row);
  });
  setCellWidget(row, Visible, visible);
  const std::pair<Column, double LabelEntry::*> values[] = {
      {Opacity, &LabelEntry::opacity}, {Surface, &LabelEntry::surfaceProbability}, {Roughness, &LabelEntry::roughness}};
  for (const auto& [column, member] : values) {
    QDoubleSpinBox* box = UnitSpinBox(e.*member);
    connect(box, &QDoubleSpinBox::valueChanged, this, [this, row, member = member](double v) {
      if (filling_) return;
      labels_[row].*member = v;
      emit labelEdited(row);
    });
    setCellWidget(row, column, box);
  }
}

}  // namespace mmrtm::viewer
