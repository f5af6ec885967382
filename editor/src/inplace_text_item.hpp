#pragma once

// Text edited in place on the canvas (a note's text, a frame's title): typed into the scene,
// committed when it loses focus or on Enter (Ctrl+Enter for several lines), dropped on Escape.

#include <QGraphicsTextItem>
#include <functional>

namespace vrflow::editor::gui {

/// An editable text over an item; deletes itself once finished.
class InPlaceTextItem : public QGraphicsTextItem {
 public:
  /// Starts editing `text` as a child of `parent`; `finished` gets the new text (not called
  /// when the user presses Escape).
  InPlaceTextItem(QGraphicsItem* parent, const QString& text, bool multiLine,
                  std::function<void(const QString&)> finished);

 protected:
  void focusOutEvent(QFocusEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;

 private:
  void finish(bool keep);

  bool multiLine_;
  bool done_ = false;
  std::function<void(const QString&)> finished_;
};

}  // namespace vrflow::editor::gui
