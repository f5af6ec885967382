#include "timeline.hpp"

#include <QFile>
#include <QFileInfo>
#include <QGraphicsLineItem>
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QPainter>
#include <QScrollBar>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "qt_text.hpp"

namespace vrflow::editor::gui {

namespace {

using nlohmann::json;

constexpr double kRowHeight = 22;
constexpr double kSpanHeight = 14;
constexpr double kLabelWidth = 190;  ///< the row labels over the left of the view
const QColor kWait(190, 196, 206);
const QColor kCompute(60, 160, 90);
const QColor kArrow(40, 80, 200, 150);

double number(const json& e, const char* key) {
  const auto it = e.find(key);
  return it != e.end() && it->is_number() ? it->get<double>() : 0;
}

int integer(const json& e, const char* key) {
  const auto it = e.find(key);
  return it != e.end() && it->is_number_integer() ? it->get<int>() : 0;
}

std::string name(const json& e) {
  const auto args = e.find("args");
  if (args == e.end() || !args->is_object() || !args->contains("name") ||
      !(*args)["name"].is_string())
    return {};
  return (*args)["name"].get<std::string>();
}

}  // namespace

TimelineView::TimelineView(QWidget* parent) : QGraphicsView(parent) {
  setScene(new QGraphicsScene(this));
  setDragMode(QGraphicsView::ScrollHandDrag);
  setTransformationAnchor(QGraphicsView::NoAnchor);  // the wheel keeps the cursor's time itself
  setRenderHint(QPainter::Antialiasing, false);
  setViewportUpdateMode(QGraphicsView::FullViewportUpdate);  // the labels follow the view
  setBackgroundBrush(Qt::white);
}

bool TimelineView::open(const QString& path) {
  QFile file(path);
  if (!file.open(QIODevice::ReadOnly)) {
    error_ = path + ": cannot be read (" + file.errorString() + ")";
    return false;
  }
  const QByteArray bytes = file.readAll();
  const json trace =
      json::parse(bytes.constData(), bytes.constData() + bytes.size(), nullptr, false);
  if (!trace.is_object() || !trace.contains("traceEvents") || !trace["traceEvents"].is_array()) {
    error_ =
        path + ": not a trace (a JSON object with \"traceEvents\", as `vrflow run --trace` writes)";
    return false;
  }
  const json& events = trace["traceEvents"];
  // Rows: one per (process, thread) = (host, module), named by the metadata events.
  std::map<int, std::string> hosts;
  std::map<std::pair<int, int>, std::string> modules;
  double first = INFINITY, last = -INFINITY;
  for (const auto& e : events) {
    if (!e.is_object() || !e.contains("ph") || !e["ph"].is_string()) continue;
    const std::string ph = e["ph"].get<std::string>();
    const std::pair<int, int> row{integer(e, "pid"), integer(e, "tid")};
    if (ph == "M" && e.value("name", "") == "process_name") hosts[row.first] = name(e);
    if (ph == "M" && e.value("name", "") == "thread_name") modules[row] = name(e);
    if (ph == "X" || ph == "s" || ph == "f") {
      if (!modules.count(row)) modules[row] = "thread " + std::to_string(row.second);
      first = std::min(first, number(e, "ts"));
      last = std::max(last, number(e, "ts") + number(e, "dur"));
    }
  }
  if (first > last) first = last = 0;

  scene()->clear();
  rows_.clear();
  spans_.clear();
  arrows_ = 0;
  std::map<std::pair<int, int>, double> rowY;
  std::map<std::pair<int, int>, QString> moduleOf;
  for (const auto& [row, module] : modules) {  // ordered by host, then module
    rowY[row] = static_cast<double>(rows_.size()) * kRowHeight;
    const auto host = hosts.find(row.first);
    const std::string hostName =
        host != hosts.end() ? host->second : "process " + std::to_string(row.first);
    rows_ << qtText(hostName + " / " + module);
    moduleOf[row] = qtText(module);
  }
  // Scene x: milliseconds since the first event; y: the row.
  const auto x = [first](double us) { return (us - first) / 1000.0; };
  std::map<std::pair<int, QString>, QPointF> flowStart;  // (id, name) -> start
  for (const auto& e : events) {
    if (!e.is_object() || !e.contains("ph") || !e["ph"].is_string()) continue;
    const std::string ph = e["ph"].get<std::string>();
    const std::pair<int, int> row{integer(e, "pid"), integer(e, "tid")};
    const auto y = rowY.find(row);
    if (y == rowY.end()) continue;
    if (ph == "X") {
      const QString kind = qtText(e.value("name", ""));
      const double begin = x(number(e, "ts")), width = number(e, "dur") / 1000.0;
      auto* span = scene()->addRect(QRectF(begin, y->second + (kRowHeight - kSpanHeight) / 2,
                                           std::max(width, 1e-4), kSpanHeight),
                                    Qt::NoPen, kind == "wait" ? kWait : kCompute);
      const auto args = e.find("args");
      const QString iteration = args != e.end() && args->is_object() && args->contains("iteration")
                                    ? QString::fromStdString((*args)["iteration"].dump())
                                    : QString("?");
      span->setToolTip(QString("%1 \u00b7 %2 \u00b7 iteration %3\nfrom %4 ms for %5 ms\n%6")
                           .arg(kind, moduleOf[row], iteration)
                           .arg(begin, 0, 'f', 3)
                           .arg(width, 0, 'f', 3)
                           .arg(rows_[static_cast<int>(y->second / kRowHeight)]));
      ++spans_[{moduleOf[row], kind}];
    } else if (ph == "s" || ph == "f") {
      const QPointF at(x(number(e, "ts")), y->second + kRowHeight / 2);
      const std::pair<int, QString> key{integer(e, "id"), qtText(e.value("name", ""))};
      if (ph == "s") {
        flowStart[key] = at;
        continue;
      }
      const auto start = flowStart.find(key);
      if (start == flowStart.end()) continue;
      QPen pen(kArrow, 1.2);
      pen.setCosmetic(true);
      auto* arrow = scene()->addLine(QLineF(start->second, at), pen);
      arrow->setZValue(1);
      arrow->setToolTip(QString("message %1\nsent at %2 ms, delivered at %3 ms")
                            .arg(key.second)
                            .arg(start->second.x(), 0, 'f', 3)
                            .arg(at.x(), 0, 'f', 3));
      flowStart.erase(start);
      ++arrows_;
    }
  }
  durationMs_ = (last - first) / 1000.0;
  // Room on the left for the labels drawn over the view.
  scene()->setSceneRect(QRectF(-durationMs_ * 0.02 - 1e-3, -kRowHeight, durationMs_ * 1.04 + 2e-3,
                               (static_cast<double>(rows_.size()) + 1.5) * kRowHeight));
  file_ = path;
  error_.clear();
  fitAll();
  Q_EMIT opened(path);
  return true;
}

int TimelineView::spanCount(const QString& module, const QString& kind) const {
  const auto it = spans_.find({module, kind});
  return it == spans_.end() ? 0 : it->second;
}

void TimelineView::fitAll() {
  const double width = std::max(50.0, viewport()->width() - kLabelWidth - 20);
  const double span = std::max(scene()->sceneRect().width(), 1e-3);
  setTransform(QTransform::fromScale(width / span, 1));
  centerOn(scene()->sceneRect().center());
  horizontalScrollBar()->setValue(horizontalScrollBar()->minimum());
  fitted_ = true;
}

void TimelineView::resizeEvent(QResizeEvent* event) {
  QGraphicsView::resizeEvent(event);
  if (fitted_ && !file_.isEmpty() &&
      transform().m11() * scene()->sceneRect().width() < viewport()->width())
    fitAll();
}

void TimelineView::wheelEvent(QWheelEvent* event) {
  // Zoom the time axis only, around the cursor; between a whole trace and a microsecond.
  const double factor = std::pow(1.25, event->angleDelta().y() / 120.0);
  const double now = transform().m11();
  const double lowest =
      (viewport()->width() - kLabelWidth) / std::max(durationMs_ * 1.04, 1e-3) / 2;
  const double wanted = std::clamp(now * factor, std::min(lowest, now), 1e6);
  const QPoint cursor = event->position().toPoint();
  const double before = mapToScene(cursor).x();
  if (wanted != now) scale(wanted / now, 1);
  QScrollBar* bar = horizontalScrollBar();
  bar->setValue(bar->value() +
                static_cast<int>(std::lround((before - mapToScene(cursor).x()) * wanted)));
  fitted_ = false;
  event->accept();
}

void TimelineView::drawForeground(QPainter* painter, const QRectF&) {
  // In view coordinates: a time axis along the top and the rows' names along the left.
  painter->save();
  painter->resetTransform();
  const QRect area = viewport()->rect();
  QFont font = painter->font();
  font.setPointSizeF(7.5);
  painter->setFont(font);
  // Ticks at 1, 2 or 5 × 10^n ms, about every 100 px.
  const double perMs = transform().m11();
  const double raw = 100 / std::max(perMs, 1e-9);
  const double power = std::pow(10, std::floor(std::log10(raw)));
  const double step = raw / power < 2 ? 2 * power : raw / power < 5 ? 5 * power : 10 * power;
  const double left = mapToScene(QPoint(static_cast<int>(kLabelWidth), 0)).x();
  const double right = mapToScene(QPoint(area.right(), 0)).x();
  painter->fillRect(QRectF(0, 0, area.width(), 16), QColor(245, 246, 248, 235));
  painter->setPen(QColor(90, 96, 106));
  for (double t = std::ceil(left / step) * step; t <= right; t += step) {
    const double px = mapFromScene(QPointF(t, 0)).x();
    painter->drawLine(QPointF(px, 12), QPointF(px, 16));
    painter->drawText(QPointF(px + 2, 11), QString::number(t, 'g', 6) + " ms");
  }
  painter->fillRect(QRectF(0, 16, kLabelWidth, area.height()), QColor(250, 250, 252, 235));
  painter->setPen(QColor(30, 40, 55));
  for (int i = 0; i < rows_.size(); ++i) {
    const double y = mapFromScene(QPointF(0, i * kRowHeight + kRowHeight / 2)).y();
    if (y < 16) continue;
    painter->drawText(QRectF(4, y - 8, kLabelWidth - 8, 16), Qt::AlignLeft | Qt::AlignVCenter,
                      painter->fontMetrics().elidedText(rows_[i], Qt::ElideLeft,
                                                        static_cast<int>(kLabelWidth - 8)));
  }
  painter->restore();
}

}  // namespace vrflow::editor::gui
