// Chooses one of the DICOM series of a folder: each with its description,
// modality, size and number of slices. Plain Qt.
#pragma once

#include <QDialog>
#include <QString>
#include <QVector>

class QTreeWidget;

namespace mmrtm::viewer {

struct SeriesInfo {
  QString uid, description, modality;
  int slices = 0, rows = 0, columns = 0;
  // What names the series to the reader: its UID, or its description when
  // the files carry no UID.
  QString key() const { return uid.isEmpty() ? description : uid; }
};

class SeriesChooserDialog : public QDialog {
  Q_OBJECT

 public:
  SeriesChooserDialog(const QString& folder, const QVector<SeriesInfo>& series, QWidget* parent = nullptr);
  // The chosen series' key (the first row is selected at the start).
  QString chosenKey() const;
  // Selects a row (tests).
  void choose(int row);

 private:
  QVector<SeriesInfo> series_;
  QTreeWidget* list_;
};

}  // namespace mmrtm::viewer
