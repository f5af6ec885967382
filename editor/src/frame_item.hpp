#pragma once

// A frame on the canvas: a titled, coloured rectangle behind the nodes; dragging it carries the
// nodes and notes inside, its corner handle resizes it, its title is edited in place.

#include <QColor>
#include <QString>
#include <functional>
#include <string>
#include <vector>

#include "resizable_item.hpp"

namespace vrflow::editor::gui {

/// A frame (`<frame>` in the file's `<editor>` section).
class FrameItem : public ResizableItem {
 public:
  FrameItem(std::string id, QSizeF size, QString title, QColor color);
  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& id() const { return id_; }
  const QString& title() const { return title_; }
  void setTitle(const QString& title);
  QColor color() const { return color_; }
  void setColor(QColor color);
  /// Starts editing the title in place.
  void editTitle();
  /// Called with the new title when an in-place edit ends (set by the canvas).
  std::function<void(const std::string& id, const QString& title)> titleEdited;

 protected:
  void mousePressEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseReleaseEvent(QGraphicsSceneMouseEvent* event) override;
  void mouseDoubleClickEvent(QGraphicsSceneMouseEvent* event) override;
  QVariant itemChange(GraphicsItemChange change, const QVariant& value) override;

 private:
  std::string id_;
  QString title_;
  QColor color_;
  /// The unselected nodes and notes inside while the frame is dragged, moved along with it.
  std::vector<QGraphicsItem*> carried_;
  QPointF lastPos_;
};

}  // namespace vrflow::editor::gui
