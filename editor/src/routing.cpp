#include "routing.hpp"

#include <algorithm>
#include <cmath>

namespace vrflow::editor::gui {

namespace {

constexpr double kClearance = 16;  // between a bent connection and the nodes it avoids
constexpr int kSamples = 48;

}  // namespace

QPainterPath connectionCurve(QPointF from, QPointF to) {
  QPainterPath path(from);
  if (to.x() < from.x() + 30) {
    // A connection going back (a feedback loop): around, below both ends, not through nodes.
    const double below = std::max(from.y(), to.y()) + 60;
    const double midX = (from.x() + to.x()) / 2;
    path.cubicTo(from + QPointF(70, 0), QPointF(from.x() + 70, below), QPointF(midX, below));
    path.cubicTo(QPointF(to.x() - 70, below), to - QPointF(70, 0), to);
    return path;
  }
  const double dx = std::max(40.0, std::abs(to.x() - from.x()) * 0.5);
  path.cubicTo(from + QPointF(dx, 0), to - QPointF(dx, 0), to);
  return path;
}

bool crosses(const QPainterPath& path, const QRectF& rect) {
  for (int i = 1; i < kSamples; ++i) {
    if (rect.contains(path.pointAtPercent(static_cast<double>(i) / kSamples))) return true;
  }
  return false;
}

QPainterPath routedCurve(QPointF from, QPointF to, const std::vector<QRectF>& obstacles) {
  QPainterPath plain = connectionCurve(from, to);
  if (to.x() < from.x() + 30) return plain;
  // The nodes strictly between both ends that the plain curve runs through.
  QRectF blocked;
  for (const QRectF& rect : obstacles) {
    if (rect.contains(from) || rect.contains(to)) continue;
    if (rect.right() < from.x() || rect.left() > to.x()) continue;
    if (crosses(plain, rect.adjusted(-4, -4, 4, 4))) blocked = blocked.united(rect);
  }
  if (blocked.isNull()) return plain;
  // Then, each time, any other node the bent lane would cross joins the block.
  for (int pass = 0; pass < 4; ++pass) {
    const QRectF lane(QPointF(blocked.left(), blocked.top() - 2 * kClearance),
                      QPointF(blocked.right(), blocked.bottom() + 2 * kClearance));
    bool grew = false;
    for (const QRectF& rect : obstacles) {
      if (rect.contains(from) || rect.contains(to) || blocked.contains(rect)) continue;
      if (rect.intersects(lane) && rect.right() > from.x() && rect.left() < to.x()) {
        blocked = blocked.united(rect);
        grew = true;
      }
    }
    if (!grew) break;
  }
  // Over or under the block, whichever is nearer to the ends.
  const double mean = (from.y() + to.y()) / 2;
  const double above = blocked.top() - kClearance;
  const double below = blocked.bottom() + kClearance;
  const double lane = std::abs(mean - above) <= std::abs(below - mean) ? above : below;
  const QPointF enter(std::max(from.x() + 20, blocked.left() - kClearance), lane);
  const QPointF leave(std::min(to.x() - 20, blocked.right() + kClearance), lane);
  QPainterPath path(from);
  const double in = std::max(20.0, (enter.x() - from.x()) * 0.5);
  path.cubicTo(from + QPointF(in, 0), enter - QPointF(in, 0), enter);
  path.lineTo(leave);
  const double out = std::max(20.0, (to.x() - leave.x()) * 0.5);
  path.cubicTo(leave + QPointF(out, 0), to - QPointF(out, 0), to);
  return path;
}

}  // namespace vrflow::editor::gui
