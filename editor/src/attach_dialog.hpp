#pragma once

#include <QDialog>
#include <QJsonObject>
#include <QList>

class QTableWidget;

namespace vrflow::editor::gui {

/// "Attach to a run": the running runs of this user (`vrflow list --json`), one per row; the
/// chosen one is followed on the canvas.
class AttachDialog : public QDialog {
  Q_OBJECT

 public:
  explicit AttachDialog(const QList<QJsonObject>& runs, QWidget* parent = nullptr);

  /// The id of the selected run (empty when none is).
  QString chosenRun() const;
  QTableWidget* table() const { return table_; }

 private:
  QTableWidget* table_;
};

}  // namespace vrflow::editor::gui
