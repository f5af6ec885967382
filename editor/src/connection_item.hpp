#pragma once

// A connection on the canvas: a curve from an output port to an input port.

#include <QColor>
#include <QGraphicsItem>
#include <QPainterPath>
#include <QString>
#include <cstddef>

namespace vrflow::editor::gui {

/// A connection: a curve from an output port to an input port, routed by the canvas.
class ConnectionItem : public QGraphicsItem {
 public:
  ConnectionItem(std::size_t index, QPainterPath path, QColor color, bool stampsOnly);
  QRectF boundingRect() const override;
  QPainterPath shape() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  /// The connection's index in Application::connections.
  std::size_t index() const { return index_; }
  void setIndex(std::size_t index) { index_ = index; }
  QColor color() const { return color_; }
  /// Replaces the curve (its ends or a node in its way moved).
  void setPath(const QPainterPath& path);
  const QPainterPath& path() const { return path_; }
  /// 0 fine, 1 warning, 2 error, 3 part of a deadlock cycle.
  void setProblem(int level) {
    problem_ = level;
    update();
  }
  int problem() const { return problem_; }
  void setLabel(const QString& text) { label_ = text; }
  const QString& label() const { return label_; }
  QPointF midPoint() const { return mid_; }

 private:
  std::size_t index_;
  QPainterPath path_;
  QColor color_;
  bool stampsOnly_;
  int problem_ = 0;
  QString label_;
  QPointF mid_;
};

}  // namespace vrflow::editor::gui
