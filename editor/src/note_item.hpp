#pragma once

// A note on the canvas: text in a yellow box; moved by dragging, resized by its corner handle,
// its text edited in place on double-click.

#include <QString>
#include <functional>
#include <string>

#include "resizable_item.hpp"

namespace vrflow::editor::gui {

/// A note (`<note>` in the file's `<editor>` section).
class NoteItem : public ResizableItem {
 public:
  NoteItem(std::string id, QSizeF size, QString text);
  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& id() const { return id_; }
  const QString& text() const { return text_; }
  void setText(const QString& text);
  /// Starts editing the text in place; `edited` gets the new text when editing ends.
  void editText();
  /// Called with the new text when an in-place edit ends (set by the canvas).
  std::function<void(const std::string& id, const QString& text)> textEdited;

 protected:
  void mouseDoubleClickEvent(QGraphicsSceneMouseEvent* event) override;

 private:
  std::string id_;
  QString text_;
};

}  // namespace vrflow::editor::gui
