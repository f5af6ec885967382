#pragma once

// How connections are drawn: a cubic curve from an output to an input, bent around the nodes in
// its way; a connection going back passes below both ends.

#include <QPainterPath>
#include <QPointF>
#include <QRectF>
#include <vector>

namespace vrflow::editor::gui {

/// The curve of a connection from an output at `from` to an input at `to` (around, below both
/// ends, when it goes back).
QPainterPath connectionCurve(QPointF from, QPointF to);

/// connectionCurve(), bent above or below the `obstacles` (node bodies, scene units) its plain
/// curve would cross; a connection going back keeps passing below its ends.
QPainterPath routedCurve(QPointF from, QPointF to, const std::vector<QRectF>& obstacles);

/// Whether `path` passes through `rect` (sampled along the curve).
bool crosses(const QPainterPath& path, const QRectF& rect);

}  // namespace vrflow::editor::gui
