#include "frame_item.hpp"

#include <QGraphicsScene>
#include <QGraphicsSceneMouseEvent>
#include <QPainter>

#include "inplace_text_item.hpp"
#include "node_item.hpp"
#include "note_item.hpp"

namespace vrflow::editor::gui {

namespace {

constexpr double kTitleHeight = 22;

}  // namespace

FrameItem::FrameItem(std::string id, QSizeF size, QString title, QColor color)
    : ResizableItem(size, QSizeF(80, 50)),
      id_(std::move(id)),
      title_(std::move(title)),
      color_(color) {
  setFlags(ItemIsMovable | ItemIsSelectable | ItemSendsGeometryChanges);
  setZValue(-1);  // behind connections and nodes
}

QRectF FrameItem::boundingRect() const {
  return QRectF(QPointF(-2, -2), size() + QSizeF(4, 4));
}

void FrameItem::setTitle(const QString& title) {
  title_ = title;
  update();
}

void FrameItem::setColor(QColor color) {
  color_ = color;
  update();
}

void FrameItem::paint(QPainter* painter, const QStyleOptionGraphicsItem*, QWidget*) {
  painter->setRenderHint(QPainter::Antialiasing);
  const QRectF box(QPointF(0, 0), size());
  QColor fill = color_;
  fill.setAlpha(40);
  painter->setBrush(fill);
  painter->setPen(isSelected() ? QPen(QColor(255, 170, 0), 2.5) : QPen(color_, 1.5));
  painter->drawRoundedRect(box, 8, 8);
  QColor band = color_;
  band.setAlpha(170);
  painter->save();
  QPainterPath clip;
  clip.addRoundedRect(box, 8, 8);
  painter->setClipPath(clip);
  painter->fillRect(QRectF(0, 0, size().width(), kTitleHeight), band);
  painter->restore();
  QFont font = painter->font();
  font.setPointSizeF(9.5);
  font.setBold(true);
  painter->setFont(font);
  painter->setPen(Qt::white);
  painter->drawText(QRectF(10, 0, size().width() - 20, kTitleHeight),
                    Qt::AlignLeft | Qt::AlignVCenter, title_);
  drawHandle(painter, color_.darker(130));
}

void FrameItem::editTitle() {
  auto* editor = new InPlaceTextItem(this, title_, false,
                                     [id = id_, callback = titleEdited](const QString& t) {
                                       if (callback) callback(id, t);
                                     });
  editor->setPos(6, 0);
  editor->setDefaultTextColor(Qt::black);
}

void FrameItem::mousePressEvent(QGraphicsSceneMouseEvent* event) {
  carried_.clear();
  if (event->button() == Qt::LeftButton && scene() != nullptr && !onHandle(event->pos())) {
    // What lies inside (by its top-left corner, as moveFrame() decides) moves with the frame.
    const QRectF area(scenePos(), size());
    for (QGraphicsItem* item : scene()->items(area)) {
      if (item->isSelected() || item->parentItem() != nullptr) continue;
      if (dynamic_cast<NodeItem*>(item) == nullptr && dynamic_cast<NoteItem*>(item) == nullptr)
        continue;
      if (area.contains(item->scenePos())) carried_.push_back(item);
    }
  }
  lastPos_ = pos();
  ResizableItem::mousePressEvent(event);
}

void FrameItem::mouseReleaseEvent(QGraphicsSceneMouseEvent* event) {
  ResizableItem::mouseReleaseEvent(event);
  carried_.clear();
}

void FrameItem::mouseDoubleClickEvent(QGraphicsSceneMouseEvent* event) {
  if (event->button() == Qt::LeftButton && event->pos().y() <= kTitleHeight) {
    editTitle();
    event->accept();
    return;
  }
  QGraphicsItem::mouseDoubleClickEvent(event);
}

QVariant FrameItem::itemChange(GraphicsItemChange change, const QVariant& value) {
  if (change == ItemPositionHasChanged) {
    const QPointF delta = pos() - lastPos_;
    lastPos_ = pos();
    for (QGraphicsItem* item : carried_) item->moveBy(delta.x(), delta.y());
  }
  return QGraphicsItem::itemChange(change, value);
}

}  // namespace vrflow::editor::gui
