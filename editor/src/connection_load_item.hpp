#pragma once

// A connection's live load on the canvas: a band behind its curve coloured by the queue's fill
// against its capacity (green, amber, red; grey when unbounded), and, while the pointer is over
// the curve, a small label with its messages/s and MiB/s at the curve's middle (never on the
// ports, never piled with its neighbours').

#include <QColor>
#include <QFont>
#include <QGraphicsObject>
#include <QPainterPath>

namespace vrflow::editor::gui {

/// The small font of the live view's labels on the canvas.
QFont overlayFont(double pointSize = 7);
/// The colour of a queue `fill` (0..1): green when empty, amber half full, red full.
QColor colorOfFill(double fill);

/// A child of a ConnectionItem, stacked behind it.
class ConnectionLoadItem : public QGraphicsObject {
  Q_OBJECT

 public:
  /// `curve` is the connection's shape (its stroked curve), `middle` the curve's midpoint.
  ConnectionLoadItem(QGraphicsItem* connection, QPainterPath curve, QPointF middle);
  /// The queue's fill (negative: unbounded) and the label ("" for none).
  void setLoad(double fill, const QString& label, const QString& tooltip);
  QColor color() const { return color_; }
  const QString& label() const { return label_; }
  /// Whether the label is drawn now (the pointer is over the curve).
  bool labelShown() const { return hovered_ && !label_.isEmpty(); }

  QRectF boundingRect() const override;
  QPainterPath shape() const override { return curve_; }
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

 protected:
  void hoverEnterEvent(QGraphicsSceneHoverEvent* event) override;
  void hoverLeaveEvent(QGraphicsSceneHoverEvent* event) override;

 private:
  QRectF labelRect() const;

  QPainterPath curve_;
  QPointF middle_;
  QColor color_;
  QString label_;
  bool hovered_ = false;
};

}  // namespace vrflow::editor::gui
