#pragma once

// A view opened over the canvas (a composite's inside, a wall): it covers its parent while open,
// under a bar with "Back" and a breadcrumb; Back or Escape in its content asks to close it.

#include <QWidget>

class QLabel;
class QToolButton;

namespace vrflow::editor::gui {

class CanvasOverlay : public QWidget {
  Q_OBJECT

 public:
  /// The breadcrumb's text.
  QString breadcrumb() const;
  QToolButton* backButton() const { return back_; }

 Q_SIGNALS:
  /// "Back" (or Escape): return to the application.
  void closeRequested();

 protected:
  /// The bar over `parent`, saying `path`; the content comes with setContent().
  CanvasOverlay(QWidget* parent, const QString& path, const QString& name);
  /// Puts `content` under the bar, then covers the parent and shows; Escape in it closes.
  void setContent(QWidget* content);
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  QLabel* path_;
  QToolButton* back_;
  QWidget* content_ = nullptr;
};

}  // namespace vrflow::editor::gui
