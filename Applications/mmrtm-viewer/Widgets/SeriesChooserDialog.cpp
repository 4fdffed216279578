#include "SeriesChooserDialog.h"

#include <QDialogButtonBox>
#include <QLabel>
#include <QTreeWidget>
#include <QVBoxLayout>

namespace mmrtm::viewer {

SeriesChooserDialog::SeriesChooserDialog(const QString& folder, const QVector<SeriesInfo>& series, QWidget* parent)
    : QDialog(parent), series_(series) {
  setWindowTitle(tr("Choose a DICOM series"));
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(new QLabel(tr("%1 holds %2 series:").arg(folder).arg(series.size())));
  list_ = new QTreeWidget;
  list_->setHeaderLabels({tr("Description"), tr("Modality"), tr("Size"), tr("Slices"), tr("Series UID")});
  list_->setRootIsDecorated(false);
  for (const SeriesInfo& s : series)
    list_->addTopLevelItem(
        new QTreeWidgetItem({s.description.isEmpty() ? tr("(no description)") : s.description, s.modality,
                             QString("%1 x %2").arg(s.columns).arg(s.rows), QString::number(s.slices), s.uid}));
  list_->resizeColumnToContents(0);
  layout->addWidget(list_);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Open | QDialogButtonBox::Cancel);
  layout->addWidget(buttons);
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  connect(list_, &QTreeWidget::itemDoubleClicked, this, &QDialog::accept);
  choose(0);
}

void SeriesChooserDialog::choose(int row) {
  if (row >= 0 && row < list_->topLevelItemCount()) list_->setCurrentItem(list_->topLevelItem(row));
}

QString SeriesChooserDialog::chosenKey() const {
  const int row = list_->indexOfTopLevelItem(list_->currentItem());
  return row >= 0 ? series_[row].key() : QString();
}

}  // namespace mmrtm::viewer
