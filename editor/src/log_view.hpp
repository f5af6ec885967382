#pragma once

#include <QPlainTextEdit>
#include <QProcess>

namespace vrflow::editor::gui {

/// One module's log, following new lines while its run goes on: the output of
/// `vrflow logs RUN MODULE --follow` (docs/operations.md), which reads `<log dir>/<module>.log`.
class LogView : public QPlainTextEdit {
  Q_OBJECT

 public:
  explicit LogView(QWidget* parent = nullptr);
  ~LogView() override;

  /// Shows `module`'s log of run `runId` from the start, and its new lines as they come.
  void follow(const QString& program, const QString& runId, const QString& module);
  /// The module shown (empty before follow()).
  const QString& module() const { return module_; }
  /// Whether it still waits for new lines (the run goes on).
  bool following() const;

 Q_SIGNALS:
  /// New text was added.
  void grew();

 private:
  void stopFollowing();

  QProcess* process_ = nullptr;
  QString module_;
};

}  // namespace vrflow::editor::gui
