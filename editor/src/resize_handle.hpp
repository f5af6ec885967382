#pragma once

// The corner handle notes and frames are resized by.

#include <QPainter>
#include <QPointF>
#include <QSizeF>

namespace vrflow::editor::gui {

/// Side of the square handle at the bottom-right corner, scene units.
inline constexpr double kHandleSize = 12;

/// Whether `pos` (item coordinates) is on the handle of an item of `size`.
inline bool onResizeHandle(QPointF pos, QSizeF size) {
  return pos.x() >= size.width() - kHandleSize && pos.y() >= size.height() - kHandleSize &&
         pos.x() <= size.width() && pos.y() <= size.height();
}

/// Draws the handle: three short diagonal strokes in the corner.
inline void drawResizeHandle(QPainter* painter, QSizeF size, QColor color) {
  painter->setPen(QPen(color, 1.2));
  for (double d = 3; d < kHandleSize; d += 4) {
    painter->drawLine(QPointF(size.width() - d, size.height() - 2),
                      QPointF(size.width() - 2, size.height() - d));
  }
}

}  // namespace vrflow::editor::gui
