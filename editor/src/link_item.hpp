#pragma once

// The traffic between two hosts on the canvas: a thick dashed band between the two hosts'
// groups of nodes, one lane in each sending host's colour, with the rates each way.

#include <QColor>
#include <QGraphicsObject>
#include <QStringList>

namespace vrflow::editor::gui {

/// One pair of hosts, drawn translucent over the nodes.
class LinkItem : public QGraphicsObject {
  Q_OBJECT

 public:
  LinkItem(QString a, QString b);
  /// Places the band between the hosts' groups (scene rectangles) with their colours.
  void place(QRectF groupA, QRectF groupB, QColor colorA, QColor colorB);
  /// The lines shown: "a → b: …" and "b → a: …"; `lost` draws the band red.
  void setRates(const QStringList& lines, bool lost);
  const QString& hostA() const { return a_; }
  const QString& hostB() const { return b_; }
  const QStringList& lines() const { return lines_; }
  bool lost() const { return lost_; }
  /// After a run its label (the totals) shows only under the pointer; the tooltip always has it.
  void setLabelOnHover(bool onHover);
  bool labelShown() const { return !lines_.isEmpty() && (!labelOnHover_ || hovered_); }

  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

 protected:
  void hoverEnterEvent(QGraphicsSceneHoverEvent* event) override;
  void hoverLeaveEvent(QGraphicsSceneHoverEvent* event) override;

 private:
  QRectF labelRect() const;

  QString a_, b_;
  QPointF from_, to_;
  QColor colorA_, colorB_;
  QStringList lines_;
  bool lost_ = false;
  bool labelOnHover_ = false;
  bool hovered_ = false;
};

}  // namespace vrflow::editor::gui
