#pragma once

// A note on the canvas: text in a yellow box; moved by dragging, resized by its corner handle,
// its text edited in place on double-click.

#include <QGraphicsItem>
#include <QString>
#include <functional>
#include <string>

namespace vrflow::editor::gui {

/// A note (`<note>` in the file's `<editor>` section).
class NoteItem : public QGraphicsItem {
 public:
  NoteItem(std::string id, QSizeF size, QString text);
  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& id() const { return id_; }
  QSizeF size() const { return size_; }
  void setSize(QSizeF size);
  const QString& text() const { return text_; }
  void setText(const QString& text);
  /// Starts editing the text in place; `edited` gets the new text when editing ends.
  void editText();
  /// Called with the new text when an in-place edit ends (set by the canvas).
  std::function<void(const std::string& id, const QString& text)> textEdited;

 protected:
  void mousePressEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseMoveEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseReleaseEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseDoubleClickEvent(QGraphicsSceneMouseEvent* event) override;

 private:
  std::string id_;
  QSizeF size_;
  QString text_;
  bool resizing_ = false;
};

}  // namespace vrflow::editor::gui
