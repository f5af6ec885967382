#include "canvas.hpp"

#include <QContextMenuEvent>
#include <QGraphicsPathItem>
#include <QGraphicsScene>
#include <QGraphicsTextItem>
#include <QKeyEvent>
#include <QMenu>
#include <QMimeData>
#include <QMouseEvent>
#include <QPainter>
#include <QScrollBar>
#include <QToolTip>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>

#include "qt_text.hpp"
#include "vrflow/editor/notes.hpp"

namespace vrflow::editor::gui {

namespace {

constexpr double kGrid = 10;

double snap(double v) {
  return std::round(v / kGrid) * kGrid;
}

}  // namespace

Canvas::Canvas(QWidget* parent) : QGraphicsView(parent), scene_(new QGraphicsScene(this)) {
  setScene(scene_);
  setRenderHints(QPainter::Antialiasing | QPainter::TextAntialiasing);
  setDragMode(QGraphicsView::RubberBandDrag);
  setTransformationAnchor(QGraphicsView::AnchorUnderMouse);
  setViewportUpdateMode(QGraphicsView::FullViewportUpdate);
  setAcceptDrops(true);
  setMouseTracking(true);
  scene_->setSceneRect(-4000, -4000, 8000, 8000);
  connect(scene_, &QGraphicsScene::selectionChanged, this, &Canvas::selectionChangedIds);
}

Canvas::~Canvas() {
  // The scene (a child) is deleted after this object: its last signals must not reach it.
  disconnect(scene_, nullptr, this, nullptr);
}

std::vector<std::string> Canvas::selectedNodes() const {
  std::vector<std::string> ids;
  if (state_.app == nullptr) return ids;
  for (const auto& id : nodeIds(*state_.app)) {
    auto it = nodes_.find(id);
    if (it != nodes_.end() && it->second->isSelected()) ids.push_back(id);
  }
  return ids;
}

std::vector<std::size_t> Canvas::selectedConnections() const {
  std::vector<std::size_t> result;
  for (const auto* item : connections_) {
    if (item->isSelected()) result.push_back(item->index());
  }
  return result;
}

void Canvas::selectOnly(const std::vector<std::string>& ids,
                        std::optional<std::size_t> connection) {
  {
    const QSignalBlocker block(scene_);
    scene_->clearSelection();
    for (const auto& id : ids) {
      if (auto* item = nodeItem(id)) item->setSelected(true);
    }
    if (connection) {
      if (auto* item = connectionItem(*connection)) item->setSelected(true);
    }
  }
  // Scroll only to what is out of sight: the view does not move under the user otherwise.
  const QRectF visible = mapToScene(viewport()->rect()).boundingRect();
  QGraphicsItem* shown = nullptr;
  if (!ids.empty()) {
    shown = nodeItem(ids.front());
  } else if (connection) {
    shown = connectionItem(*connection);
  }
  if (shown != nullptr && !visible.intersects(shown->sceneBoundingRect()))
    ensureVisible(shown, 80, 80);
  Q_EMIT selectionChangedIds();
}

NodeItem* Canvas::nodeItem(const std::string& id) const {
  auto it = nodes_.find(id);
  return it == nodes_.end() ? nullptr : it->second;
}

PortItem* Canvas::portItem(const std::string& node, const std::string& port) const {
  NodeItem* item = nodeItem(node);
  if (item == nullptr) return nullptr;
  for (PortItem* p : item->ports()) {
    if (p->spec().name == port) return p;
  }
  return nullptr;
}

ConnectionItem* Canvas::connectionItem(std::size_t index) const {
  for (auto* item : connections_) {
    if (item->index() == index) return item;
  }
  return nullptr;
}

QPointF Canvas::portScenePos(const std::string& node, const std::string& port) const {
  const PortItem* item = portItem(node, port);
  return item == nullptr ? QPointF() : item->scenePos();
}

void Canvas::fitAll() {
  QRectF bounds;
  for (const auto& [id, item] : nodes_) bounds = bounds.united(item->sceneBoundingRect());
  for (const auto* item : connections_) bounds = bounds.united(item->path().boundingRect());
  for (const auto& [id, item] : notes_) bounds = bounds.united(item->sceneBoundingRect());
  for (const auto& [id, item] : frames_) bounds = bounds.united(item->sceneBoundingRect());
  if (bounds.isEmpty()) {
    resetTransform();
    centerOn(0, 0);
    return;
  }
  bounds = bounds.adjusted(-30, -30, 30, 30);
  // As far out as the graph needs, but never blown up beyond its natural size.
  const double scale =
      std::min({1.0, viewport()->width() / bounds.width(), viewport()->height() / bounds.height()});
  setTransform(QTransform::fromScale(scale, scale));
  centerOn(bounds.center());
}

Positions Canvas::nodeSizes() const {
  Positions sizes;
  for (const auto& [id, item] : nodes_) {
    // Room for the labels around rhombi and the run text under nodes.
    const double extra = item->kind() == NodeKind::Filter ? 70 : 0;
    sizes[id] = {item->size().width() + extra, item->size().height() + 30};
  }
  return sizes;
}

std::optional<std::string> Canvas::refusalBetween(const PortItem* from, const PortItem* to) const {
  if (from == nullptr || to == nullptr || state_.app == nullptr)
    return std::string("no port there");
  if (from == to) return std::string("a port cannot be connected to itself");
  // Dragging may start at either end: the output is the source.
  const PortItem* out = from->spec().isInput ? to : from;
  const PortItem* in = from->spec().isInput ? from : to;
  if (out->spec().isInput == in->spec().isInput) {
    return std::string(out->spec().isInput
                           ? "both ports are inputs: connect an output to an input"
                           : "both ports are outputs: connect an output to an input");
  }
  return connectionRefusal(*state_.app, *state_.catalog, out->endpoint(), in->endpoint());
}

QPointF Canvas::dropPoint() const {
  return mapToScene(viewport()->rect().center());
}

PortItem* Canvas::portAt(QPoint viewPos) const {
  const QPointF scenePos = mapToScene(viewPos);
  PortItem* best = nullptr;
  double bestDistance = 12.0 / std::max(0.2, transform().m11());
  for (const auto& [id, node] : nodes_) {
    for (PortItem* port : node->ports()) {
      const double d = QLineF(port->scenePos(), scenePos).length();
      if (d <= bestDistance) {
        bestDistance = d;
        best = port;
      }
    }
  }
  return best;
}

NodeItem* Canvas::nodeAt(QPoint viewPos) const {
  for (QGraphicsItem* item : items(viewPos)) {
    if (auto* node = dynamic_cast<NodeItem*>(item)) {
      if (node->shape().contains(node->mapFromScene(mapToScene(viewPos)))) return node;
    }
  }
  return nullptr;
}

void Canvas::mousePressEvent(QMouseEvent* event) {
  if (event->button() == Qt::MiddleButton) {
    panning_ = true;
    panLast_ = event->position().toPoint();
    setCursor(Qt::ClosedHandCursor);
    event->accept();
    return;
  }
  // A right click on empty canvas keeps the selection (its menu may frame it).
  if (event->button() == Qt::RightButton && itemAt(event->position().toPoint()) == nullptr) {
    event->accept();
    return;
  }
  if (event->button() == Qt::LeftButton) {
    if (PortItem* port = portAt(event->position().toPoint())) {
      dragFrom_ = port;
      dragLine_ = new QGraphicsPathItem;
      dragLine_->setPen(QPen(colorOfData(port->spec().data), 2, Qt::DashLine));
      dragLine_->setZValue(5);
      scene_->addItem(dragLine_);
      event->accept();
      return;
    }
  }
  QGraphicsView::mousePressEvent(event);
}

void Canvas::mouseMoveEvent(QMouseEvent* event) {
  if (panning_) {
    const QPoint delta = event->position().toPoint() - panLast_;
    panLast_ = event->position().toPoint();
    horizontalScrollBar()->setValue(horizontalScrollBar()->value() - delta.x());
    verticalScrollBar()->setValue(verticalScrollBar()->value() - delta.y());
    event->accept();
    return;
  }
  trackDrag(event);
  if (dragFrom_ != nullptr) {
    const QPointF start = dragFrom_->scenePos();
    const QPointF end = mapToScene(event->position().toPoint());
    dragLine_->setPath(dragFrom_->spec().isInput ? connectionCurve(end, start)
                                                 : connectionCurve(start, end));
    for (const auto& [id, node] : nodes_) {
      for (PortItem* port : node->ports()) port->setHighlight(0);
    }
    if (PortItem* target = portAt(event->position().toPoint());
        target != nullptr && target != dragFrom_) {
      const auto why = refusalBetween(dragFrom_, target);
      target->setHighlight(why ? -1 : 1);
      if (why) {
        QToolTip::showText(event->globalPosition().toPoint(), QString::fromStdString(*why),
                           viewport());
      } else {
        QToolTip::hideText();
      }
    }
    event->accept();
    return;
  }
  QGraphicsView::mouseMoveEvent(event);
  // Nodes dragged (or carried by a frame): their connections follow as they go.
  if (QGraphicsItem* grabber = scene_->mouseGrabberItem();
      (event->buttons() & Qt::LeftButton) &&
      (dynamic_cast<NodeItem*>(grabber) != nullptr || dynamic_cast<FrameItem*>(grabber) != nullptr))
    routeConnections();
}

void Canvas::mouseReleaseEvent(QMouseEvent* event) {
  if (panning_ && event->button() == Qt::MiddleButton) {
    panning_ = false;
    unsetCursor();
    event->accept();
    return;
  }
  if (dragFrom_ != nullptr && event->button() == Qt::LeftButton) {
    PortItem* from = dragFrom_;
    dragFrom_ = nullptr;
    delete dragLine_;
    dragLine_ = nullptr;
    for (const auto& [id, node] : nodes_) {
      for (PortItem* port : node->ports()) port->setHighlight(0);
    }
    PortItem* target = portAt(event->position().toPoint());
    if (target != nullptr && target != from) {
      if (const auto why = refusalBetween(from, target)) {
        lastRefusal_ = QString::fromStdString(*why);
        QToolTip::showText(event->globalPosition().toPoint(), lastRefusal_, viewport());
      } else {
        lastRefusal_.clear();
        const PortItem* out = from->spec().isInput ? target : from;
        const PortItem* in = from->spec().isInput ? from : target;
        Q_EMIT connectRequested(out->endpoint(), in->endpoint());
      }
    } else if (target == nullptr) {
      offerNodesForWire(from, event->position().toPoint());
    }
    event->accept();
    return;
  }
  QGraphicsView::mouseReleaseEvent(event);
  if (event->button() != Qt::LeftButton || state_.app == nullptr) return;
  if (dropSelectionOnWire()) return;
  // Nodes dragged to a new place: snap to the grid and report where.
  Positions moved;
  for (const auto& [id, item] : nodes_) {
    if (!item->isSelected()) continue;
    const QPointF pos(snap(item->pos().x()), snap(item->pos().y()));
    const auto* saved = app::findEditorNode(*state_.app, id);
    double x0 = 0, y0 = 0;
    if (saved != nullptr) {
      x0 = saved->x;
      y0 = saved->y;
    } else if (auto it = state_.fallback.find(id); it != state_.fallback.end()) {
      std::tie(x0, y0) = it->second;
    }
    if (std::abs(item->pos().x() - x0) > 0.5 || std::abs(item->pos().y() - y0) > 0.5) {
      moved[id] = {pos.x(), pos.y()};
    }
  }
  if (!moved.empty()) Q_EMIT nodesMoved(moved);
  reportNoteAndFrameChanges();
}

void Canvas::wheelEvent(QWheelEvent* event) {
  const double factor = std::pow(1.0015, event->angleDelta().y());
  const double scale = transform().m11() * factor;
  if (scale < 0.1 || scale > 4) return;
  this->scale(factor, factor);
  event->accept();
}

bool Canvas::event(QEvent* event) {
  // Delete with notes or frames selected is the canvas' key, not the Edit menu's shortcut
  // (which deletes nodes and connections only).
  if (event->type() == QEvent::ShortcutOverride) {
    const auto* key = static_cast<QKeyEvent*>(event);
    if ((key->key() == Qt::Key_Delete || key->key() == Qt::Key_Backspace) &&
        scene_->focusItem() == nullptr && !selectedNotesAndFrames().empty()) {
      event->accept();
      return true;
    }
  }
  return QGraphicsView::event(event);
}

void Canvas::keyPressEvent(QKeyEvent* event) {
  // Text typed into a note or a frame's title goes there.
  const bool typing = scene_->focusItem() != nullptr &&
                      (scene_->focusItem()->flags() & QGraphicsItem::ItemIsFocusable) != 0 &&
                      dynamic_cast<QGraphicsTextItem*>(scene_->focusItem()) != nullptr;
  if (!typing && (event->key() == Qt::Key_Delete || event->key() == Qt::Key_Backspace)) {
    const auto annotations = selectedNotesAndFrames();
    if (!annotations.empty()) requestEdit(removeNotesAndFrames(*state_.app, annotations));
    Q_EMIT deleteRequested();
    event->accept();
    return;
  }
  if (!typing && quickAddKey(event)) return;
  QGraphicsView::keyPressEvent(event);
}

void Canvas::contextMenuEvent(QContextMenuEvent* event) {
  if (NodeItem* node = nodeAt(event->pos())) {
    if (!node->isSelected()) selectOnly({node->id()});
    Q_EMIT contextMenuForNodes(selectedNodes(), event->globalPos());
    return;
  }
  // A frame's menu, a note's, or the canvas' own (add a note, a frame).
  if (QMenu* menu = contextMenuAt(event->pos())) {
    menu->setAttribute(Qt::WA_DeleteOnClose);
    menu->popup(event->globalPos());
  }
}

namespace {
// Drops are always copies: a move would make the palette or the hosts table drop the row.
void acceptAsCopy(QDropEvent* event) {
  event->setDropAction(Qt::CopyAction);
  event->accept();
}
}  // namespace

void Canvas::dragEnterEvent(QDragEnterEvent* event) {
  if (event->mimeData()->hasFormat(kNodeMime) || event->mimeData()->hasFormat(kHostMime)) {
    acceptAsCopy(event);
  }
}

void Canvas::dragMoveEvent(QDragMoveEvent* event) {
  if (event->mimeData()->hasFormat(kNodeMime)) {
    hoverWireForSpec(QString::fromUtf8(event->mimeData()->data(kNodeMime)),
                     event->position().toPoint());
    acceptAsCopy(event);
  } else if (event->mimeData()->hasFormat(kHostMime)) {
    if (nodeAt(event->position().toPoint()) != nullptr) {
      acceptAsCopy(event);
    } else {
      event->ignore();
    }
  }
}

void Canvas::dropEvent(QDropEvent* event) {
  const QMimeData* mime = event->mimeData();
  if (mime->hasFormat(kNodeMime) &&
      dropSpecOnWire(QString::fromUtf8(mime->data(kNodeMime)), event->position().toPoint())) {
    acceptAsCopy(event);
  } else if (mime->hasFormat(kNodeMime)) {
    const QPointF at = mapToScene(event->position().toPoint());
    Q_EMIT addRequested(QString::fromUtf8(mime->data(kNodeMime)),
                        QPointF(snap(at.x()), snap(at.y())));
    acceptAsCopy(event);
  } else if (mime->hasFormat(kHostMime)) {
    if (NodeItem* node = nodeAt(event->position().toPoint())) {
      Q_EMIT hostDropped(QString::fromUtf8(mime->data(kHostMime)), node->id());
      acceptAsCopy(event);
    }
  }
}

void Canvas::drawBackground(QPainter* painter, const QRectF& rect) {
  painter->fillRect(rect, QColor(236, 238, 242));
  const double step = 20;
  QPen minor(QColor(222, 225, 231), 0);
  painter->setPen(minor);
  const double left = std::floor(rect.left() / step) * step;
  const double top = std::floor(rect.top() / step) * step;
  if (transform().m11() < 0.4) return;
  QVector<QLineF> lines;
  for (double x = left; x < rect.right(); x += step)
    lines.append(QLineF(x, rect.top(), x, rect.bottom()));
  for (double y = top; y < rect.bottom(); y += step)
    lines.append(QLineF(rect.left(), y, rect.right(), y));
  painter->drawLines(lines);
}

}  // namespace vrflow::editor::gui
