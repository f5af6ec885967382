#pragma once

// The timeline (a dock): a run's trace (`--trace FILE.json`, the Chrome/Perfetto trace-event
// file the runtime writes, docs/cluster.md) drawn per host and module: wait and compute spans,
// and each message as an arrow from its sender's put() to the wait() that delivered it. The
// wheel zooms the time axis under the cursor, a drag pans; each span has a tooltip.

#include <QGraphicsView>
#include <QString>
#include <QStringList>
#include <map>

namespace vrflow::editor::gui {

class TimelineView : public QGraphicsView {
  Q_OBJECT

 public:
  explicit TimelineView(QWidget* parent = nullptr);
  /// Reads and draws a trace; on failure keeps the current one and sets error() (false).
  bool open(const QString& path);
  /// Why the last open() failed ("FILE: ...").
  const QString& error() const { return error_; }
  const QString& file() const { return file_; }
  /// The rows, top to bottom: "host a (127.0.0.1) / chain".
  const QStringList& rows() const { return rows_; }
  /// How many spans of `kind` ("wait", "compute") the row of `module` has.
  int spanCount(const QString& module, const QString& kind) const;
  int arrowCount() const { return arrows_; }
  /// Milliseconds of trace from the first event to the last.
  double durationMs() const { return durationMs_; }
  /// Pixels per millisecond of the time axis now.
  double pixelsPerMs() const { return transform().m11(); }
  /// Shows the whole trace.
  void fitAll();

 Q_SIGNALS:
  /// A trace was opened (its file).
  void opened(const QString& path);

 protected:
  void wheelEvent(QWheelEvent* event) override;
  void drawForeground(QPainter* painter, const QRectF& rect) override;
  void resizeEvent(QResizeEvent* event) override;

 private:
  QString error_, file_;
  QStringList rows_;
  std::map<std::pair<QString, QString>, int> spans_;  ///< (module, kind) -> count
  int arrows_ = 0;
  double durationMs_ = 0;
  bool fitted_ = false;
};

}  // namespace vrflow::editor::gui
