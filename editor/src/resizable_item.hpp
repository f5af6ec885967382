#pragma once

// What notes and frames share: a size, and a handle at the bottom-right corner that resizes
// them when dragged.

#include <QGraphicsItem>
#include <QSizeF>

namespace vrflow::editor::gui {

/// An item of a given size with a resize handle at its bottom-right corner.
class ResizableItem : public QGraphicsItem {
 public:
  ResizableItem(QSizeF size, QSizeF minimum) : size_(size), minimum_(minimum) {}
  QSizeF size() const { return size_; }
  void setSize(QSizeF size);

 protected:
  /// Whether `pos` (item coordinates) is on the handle.
  bool onHandle(QPointF pos) const;
  /// Draws the handle: short diagonal strokes in the corner.
  void drawHandle(QPainter* painter, QColor color) const;
  void mousePressEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseMoveEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseReleaseEvent(QGraphicsSceneMouseEvent* event) override;

 private:
  QSizeF size_;
  QSizeF minimum_;
  bool resizing_ = false;
};

}  // namespace vrflow::editor::gui
