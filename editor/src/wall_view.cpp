#include "wall_view.hpp"

#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QGraphicsTextItem>
#include <QGraphicsView>
#include <cmath>

#include "canvas_style.hpp"
#include "qt_text.hpp"

namespace vrflow::editor::gui {
namespace {

// Scene units are millimetres of the wall.
constexpr double kMm = 1000.0;

QString metres(double m) {
  return m >= 0.1 ? QString::number(m, 'g', 3) + " m" : QString::number(m * 100, 'g', 3) + " cm";
}

}  // namespace

WallView::WallView(QWidget* parent, viewer::Wall wall, const app::Application& app,
                   const QString& path)
    : CanvasOverlay(parent, path, "wallView"), wall_(std::move(wall)), view_(new QGraphicsView) {
  view_->setScene(new QGraphicsScene(view_));
  view_->setRenderHint(QPainter::Antialiasing);
  view_->setBackgroundBrush(QColor(245, 245, 245));
  build(app);
  setContent(view_);
  view_->setFocus();
}

void WallView::build(const app::Application& app) {
  QGraphicsScene* scene = view_->scene();
  const double pitchX = wall_.sizeX + wall_.bezelX - wall_.overlapX;
  const double pitchY = wall_.sizeY + wall_.bezelY - wall_.overlapY;
  const double width = wall_.cols * pitchX - wall_.bezelX + wall_.overlapX;
  const double height = wall_.rows * pitchY - wall_.bezelY + wall_.overlapY;
  // The wall's frame: what shows between the tiles is its mullions.
  auto* frame =
      scene->addRect(0, 0, width * kMm, height * kMm, QPen(Qt::NoPen), QColor(25, 25, 25));
  frame->setZValue(-1);
  const double font = std::max(12.0, wall_.sizeY * kMm / 9);
  for (const auto& tile : wall_.tiles) {
    QColor colour(150, 150, 150);
    QString address;
    for (std::size_t i = 0; i < app.hosts.size(); ++i) {
      if (app.hosts[i].id != tile.host) continue;
      colour = colorOfHost(i);
      address = qtText(app.hosts[i].address);
    }
    const QRectF rect(tile.col * pitchX * kMm, tile.row * pitchY * kMm, wall_.sizeX * kMm,
                      wall_.sizeY * kMm);
    QColor fill = colour.lighter(170);
    if (wall_.overlapX > 0 || wall_.overlapY > 0) fill.setAlpha(200);  // overlaps show through
    auto* item = scene->addRect(rect, QPen(colour.darker(130), font / 6), fill);
    item->setToolTip(QString("tile %1: column %2, row %3 (from the top left), file line %4")
                         .arg(qtText(tile.id))
                         .arg(tile.col)
                         .arg(tile.row)
                         .arg(tile.line));
    const QString window =
        tile.window == "fullscreen" ? QString("full screen") : "window at " + qtText(tile.window);
    const QString text =
        QString("%1\nhost %2%3\ndisplay %4\n%5 \u00D7 %6 px, %7")
            .arg(qtText(tile.id), qtText(tile.host),
                 address.isEmpty() ? QString() : " (" + address + ")", qtText(tile.display))
            .arg(wall_.pixelsX)
            .arg(wall_.pixelsY)
            .arg(window);
    auto* label = scene->addText(text);
    QFont f = label->font();
    f.setPixelSize(static_cast<int>(font));
    label->setFont(f);
    label->setDefaultTextColor(QColor(20, 20, 20));
    label->setPos(rect.topLeft() + QPointF(font / 2, font / 4));
    tiles_[tile.id] = item;
    texts_[tile.id] = text;
  }
  scene->setSceneRect(QRectF(0, 0, width * kMm, height * kMm).adjusted(-40, -40, 40, 40));
}

QGraphicsRectItem* WallView::tileItem(const std::string& id) const {
  const auto it = tiles_.find(id);
  return it == tiles_.end() ? nullptr : it->second;
}

QString WallView::tileText(const std::string& id) const {
  const auto it = texts_.find(id);
  return it == texts_.end() ? QString() : it->second;
}

void WallView::resizeEvent(QResizeEvent* event) {
  QWidget::resizeEvent(event);
  view_->fitInView(view_->scene()->sceneRect(), Qt::KeepAspectRatio);
}

QString WallView::describe(const viewer::Wall& wall) {
  QString text = QString("%1 \u00D7 %2 tiles of %3 \u00D7 %4")
                     .arg(wall.cols)
                     .arg(wall.rows)
                     .arg(metres(wall.sizeX), metres(wall.sizeY));
  if (wall.bezelX > 0 || wall.bezelY > 0) text += ", mullions " + metres(wall.bezelX);
  if (wall.overlapX > 0 || wall.overlapY > 0) text += ", overlap " + metres(wall.overlapX);
  return text;
}

}  // namespace vrflow::editor::gui
