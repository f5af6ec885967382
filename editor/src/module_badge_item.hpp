#pragma once

// A module's live figures under its node on the canvas: state, iterations/s, the wait vs compute
// share, CPU and memory, and a sparkline of its rate; a failed module (or one on a lost host)
// is outlined red with its cause.

#include <QGraphicsObject>
#include <QStringList>
#include <deque>

namespace vrflow::editor::gui {

/// What a badge shows (one module, or the sum over a composite instance's modules).
struct BadgeFigures {
  QString state;
  double rate = 0;       ///< iterations/s
  double waitShare = 0;  ///< 0..1
  double cpu = 0;        ///< cores
  double rssMiB = 0;
  uint64_t iterations = 0;
  int modules = 1;             ///< how many modules these figures sum
  std::deque<double> history;  ///< rate over the last minute
  QString failure;             ///< why it failed, or why its host was lost (empty when fine)
};

/// A child of a NodeItem, drawn just below the node's body.
class ModuleBadgeItem : public QGraphicsObject {
  Q_OBJECT

 public:
  /// `nodeSize` is the node's body (the badge sits under it and outlines it on failure).
  ModuleBadgeItem(QGraphicsItem* node, QSizeF nodeSize);
  void setFigures(const BadgeFigures& figures);
  const BadgeFigures& figures() const { return figures_; }
  /// The lines of text shown (for tests and the tooltip).
  const QStringList& lines() const { return lines_; }
  bool failed() const { return !figures_.failure.isEmpty(); }

  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

 private:
  QSizeF nodeSize_;
  BadgeFigures figures_;
  QStringList lines_;
};

}  // namespace vrflow::editor::gui
