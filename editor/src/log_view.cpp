#include "log_view.hpp"

#include <QScrollBar>

namespace vrflow::editor::gui {

LogView::LogView(QWidget* parent) : QPlainTextEdit(parent) {
  setReadOnly(true);
  setMaximumBlockCount(20000);
  QFont mono("monospace");
  mono.setStyleHint(QFont::Monospace);
  setFont(mono);
  setPlaceholderText("Right-click a module, \"Show log\", once it ran");
}

LogView::~LogView() {
  stopFollowing();
}

bool LogView::following() const {
  return process_ != nullptr && process_->state() != QProcess::NotRunning;
}

void LogView::stopFollowing() {
  if (process_ == nullptr) return;
  process_->disconnect(this);
  if (process_->state() != QProcess::NotRunning) {
    process_->terminate();
    if (!process_->waitForFinished(3000)) process_->kill();
    process_->waitForFinished(1000);
  }
  delete process_;
  process_ = nullptr;
}

void LogView::follow(const QString& program, const QString& runId, const QString& module) {
  stopFollowing();
  clear();
  module_ = module;
  process_ = new QProcess(this);
  auto append = [this](const QByteArray& bytes) {
    if (bytes.isEmpty()) return;
    const bool atEnd = verticalScrollBar()->value() == verticalScrollBar()->maximum();
    moveCursor(QTextCursor::End);
    insertPlainText(QString::fromUtf8(bytes));
    if (atEnd) verticalScrollBar()->setValue(verticalScrollBar()->maximum());
    Q_EMIT grew();
  };
  connect(process_, &QProcess::readyReadStandardOutput, this,
          [this, append] { append(process_->readAllStandardOutput()); });
  // A refusal (no such module, no run) is shown where the log would be.
  connect(process_, &QProcess::readyReadStandardError, this,
          [this, append] { append(process_->readAllStandardError()); });
  process_->start(program, {"logs", runId, module, "--follow"});
}

}  // namespace vrflow::editor::gui
