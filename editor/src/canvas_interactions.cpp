// The canvas' interactions beyond selecting, moving and connecting: quick-add by typing or by
// releasing a wire over empty space, dropping a node on a connection to insert it, where pastes
// land, and composites opened (drill down) or made from a selection.
#include <QApplication>
#include <QCursor>
#include <QDragLeaveEvent>
#include <QGraphicsDropShadowEffect>
#include <QGraphicsScene>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QToolTip>
#include <cmath>

#include "canvas.hpp"
#include "composite_view.hpp"
#include "qt_text.hpp"
#include "quick_add.hpp"
#include "vrflow/editor/structure_edit.hpp"

namespace vrflow::editor::gui {

namespace {

double snapped(double v) {
  return std::round(v / 10) * 10;
}

QStringList qtList(const std::vector<std::string>& texts) {
  QStringList list;
  for (const auto& t : texts) list << qtText(t);
  return list;
}

}  // namespace

std::optional<QPointF> Canvas::cursorScenePos() const {
  const QPoint at = viewport()->mapFromGlobal(QCursor::pos());
  if (!viewport()->rect().contains(at) || !isVisible()) return std::nullopt;
  return mapToScene(at);
}

void Canvas::setReadOnly(bool readOnly) {
  readOnly_ = readOnly;
  setInteractive(!readOnly);
  setAcceptDrops(!readOnly);
  setDragMode(readOnly ? QGraphicsView::ScrollHandDrag : QGraphicsView::RubberBandDrag);
}

// ---- Quick-add ---------------------------------------------------------------------------

void Canvas::openQuickAdd(QPoint at, const QString& text, const PortItem* wireFrom) {
  if (state_.app == nullptr || readOnly_) return;
  if (quickAdd_ == nullptr) {
    quickAdd_ = new QuickAdd(this);
    connect(quickAdd_, &QuickAdd::chosen, this, &Canvas::quickAddChosen);
  }
  quickAddAt_ = mapToScene(at);
  quickAddWire_.reset();
  QString title = "Add a node";
  std::vector<std::string> specs;
  if (wireFrom != nullptr) {
    quickAddWire_ = wireFrom->endpoint();
    quickAddWireIsOutput_ = !wireFrom->spec().isInput;
    specs =
        compatibleNodeSpecs(*state_.app, *state_.catalog, &*quickAddWire_, quickAddWireIsOutput_);
    title = qtText("Connect to " + app::toString(*quickAddWire_));
  } else {
    specs = compatibleNodeSpecs(*state_.app, *state_.catalog);
  }
  quickAdd_->open(viewport()->mapTo(this, at), qtList(specs), text, title);
}

bool Canvas::quickAddKey(QKeyEvent* event) {
  if (state_.app == nullptr || readOnly_ || event->modifiers() & ~Qt::ShiftModifier) return false;
  const QString text = event->text();
  const bool letter = text.size() == 1 && text[0].isLetter();
  if (!letter && event->key() != Qt::Key_Space) return false;
  const QPoint at = viewport()->mapFromGlobal(QCursor::pos());
  openQuickAdd(viewport()->rect().contains(at) ? at : viewport()->rect().center(),
               letter ? text : QString());
  event->accept();
  return true;
}

bool Canvas::focusNextPrevChild(bool next) {
  // Tab inside the popup, or the popup hiding (Qt moves the focus on), opens nothing; Tab from an
  // opened composite goes on as usual.
  const QWidget* focus = QApplication::focusWidget();
  if (quickAdd_ != nullptr &&
      (quickAdd_->isVisible() || focus == quickAdd_ || quickAdd_->isAncestorOf(focus)))
    return true;
  if (compositeView_ != nullptr || readOnly_ || state_.app == nullptr)
    return QGraphicsView::focusNextPrevChild(next);
  // Tab on the canvas opens quick-add, as in node editors, instead of leaving the canvas.
  const QPoint at = viewport()->mapFromGlobal(QCursor::pos());
  openQuickAdd(viewport()->rect().contains(at) ? at : viewport()->rect().center());
  return true;
}

bool Canvas::offerNodesForWire(const PortItem* from, QPoint at) {
  if (readOnly_ || nodeAt(at) != nullptr) return false;
  openQuickAdd(at, {}, from);
  return true;
}

void Canvas::quickAddChosen(const QString& spec) {
  const QPointF at(snapped(quickAddAt_.x()), snapped(quickAddAt_.y()));
  if (!quickAddWire_) {
    Q_EMIT addRequested(spec, at);
    setFocus();
    return;
  }
  std::string id;
  auto edit = addNodeFromSpec(*state_.app, *state_.catalog, stdText(spec), at.x(), at.y(),
                              &*quickAddWire_, quickAddWireIsOutput_, &id);
  quickAddWire_.reset();
  setFocus();
  if (!edit) {
    lastRefusal_ = qtText(edit.error().message);
    Q_EMIT messageRequested(lastRefusal_);
    return;
  }
  Q_EMIT editRequested(*edit, {id});
}

// ---- Drop on a wire ----------------------------------------------------------------------

std::optional<std::size_t> Canvas::wireAt(QPoint viewPos, const std::string& node) const {
  for (QGraphicsItem* item : items(viewPos)) {
    auto* wire = dynamic_cast<ConnectionItem*>(item);
    if (wire == nullptr || state_.app == nullptr || wire->index() >= state_.app->connections.size())
      continue;
    const auto& c = state_.app->connections[wire->index()];
    if (c.from.node != node && c.to.node != node) return wire->index();
  }
  return std::nullopt;
}

void Canvas::setWireHover(std::optional<std::size_t> index,
                          const std::optional<std::string>& refusal, QPoint at) {
  if (wireShown_ && wireShown_ != index) {
    if (auto* item = connectionItem(*wireShown_)) item->setGraphicsEffect(nullptr);
  }
  wireShown_ = index;
  wireHover_ = index && !refusal ? index : std::nullopt;
  if (!index) return;
  if (auto* item = connectionItem(*index)) {
    auto* glow = new QGraphicsDropShadowEffect;
    glow->setOffset(0, 0);
    glow->setBlurRadius(16);
    glow->setColor(refusal ? QColor(220, 40, 40) : QColor(40, 160, 255));
    item->setGraphicsEffect(glow);
  }
  if (refusal) {
    lastRefusal_ = qtText(*refusal);
    QToolTip::showText(viewport()->mapToGlobal(at), lastRefusal_, viewport());
  } else {
    QToolTip::hideText();
  }
}

void Canvas::trackDrag(QMouseEvent* event) {
  // Only while exactly one node is dragged with the left button.
  const auto* grabbed = dynamic_cast<NodeItem*>(scene_->mouseGrabberItem());
  if (readOnly_ || grabbed == nullptr || !(event->buttons() & Qt::LeftButton) ||
      selectedNodes().size() != 1) {
    if (wireShown_) setWireHover(std::nullopt, std::nullopt, {});
    return;
  }
  const QPoint at = event->position().toPoint();
  const auto wire = wireAt(at, grabbed->id());
  std::optional<std::string> refusal;
  if (wire) {
    auto edit = insertOnConnection(*state_.app, *state_.catalog, grabbed->id(), *wire);
    if (!edit) refusal = edit.error().message;
  }
  setWireHover(wire, refusal, at);
}

bool Canvas::dropSelectionOnWire() {
  const auto wire = wireHover_;
  const bool shown = wireShown_.has_value();
  setWireHover(std::nullopt, std::nullopt, {});
  if (!wire) {
    if (shown) Q_EMIT messageRequested(lastRefusal_);
    return false;
  }
  const auto ids = selectedNodes();
  if (ids.size() != 1) return false;
  const NodeItem* item = nodeItem(ids.front());
  const std::pair<double, double> at{snapped(item->pos().x()), snapped(item->pos().y())};
  auto edit = insertOnConnection(*state_.app, *state_.catalog, ids.front(), *wire, at);
  if (!edit) return false;
  lastRefusal_.clear();
  Q_EMIT editRequested(*edit, ids);
  return true;
}

namespace {
// The node a palette spec adds, then inserted on connection `wire`, as one edit.
Result<Edit> addAndInsert(const app::Application& app, const app::Catalog& catalog,
                          const QString& spec, QPointF at, std::size_t wire, std::string& id) {
  auto added = addNodeFromSpec(app, catalog, stdText(spec), at.x(), at.y(), nullptr, true, &id);
  if (!added) return added;
  auto inserted = insertOnConnection(added->after, catalog, id, wire);
  if (!inserted) return inserted;
  return Edit{"Insert new " + id + inserted->label.substr(inserted->label.find(" on ")), app,
              std::move(inserted->after)};
}
}  // namespace

void Canvas::hoverWireForSpec(const QString& spec, QPoint at) {
  if (readOnly_ || state_.app == nullptr) return;
  const auto wire = wireAt(at, {});
  std::optional<std::string> refusal;
  if (wire) {
    std::string id;
    auto edit = addAndInsert(*state_.app, *state_.catalog, spec, mapToScene(at), *wire, id);
    if (!edit) refusal = edit.error().message;
  }
  setWireHover(wire, refusal, at);
}

void Canvas::dragLeaveEvent(QDragLeaveEvent* event) {
  setWireHover(std::nullopt, std::nullopt, {});  // a palette drag left: no wire stays lit
  QGraphicsView::dragLeaveEvent(event);
}

bool Canvas::dropSpecOnWire(const QString& spec, QPoint at) {
  const auto wire = wireHover_;
  setWireHover(std::nullopt, std::nullopt, {});
  if (!wire || readOnly_ || state_.app == nullptr) return false;
  const QPointF scenePos = mapToScene(at);
  std::string id;
  auto edit = addAndInsert(*state_.app, *state_.catalog, spec,
                           {snapped(scenePos.x()), snapped(scenePos.y())}, *wire, id);
  if (!edit) return false;
  Q_EMIT editRequested(*edit, {id});
  return true;
}

// ---- Composites --------------------------------------------------------------------------

void Canvas::collapseSelection() {
  if (state_.app == nullptr || readOnly_) return;
  std::string id;
  auto edit = collapseToComposite(*state_.app, selectedNodes(), "group", &id);
  if (!edit) {
    lastRefusal_ = qtText(edit.error().message);
    Q_EMIT messageRequested(lastRefusal_);
    return;
  }
  Q_EMIT editRequested(*edit, {id});
}

void Canvas::mouseDoubleClickEvent(QMouseEvent* event) {
  NodeItem* node = nodeAt(event->position().toPoint());
  if (event->button() == Qt::LeftButton && node != nullptr && !readOnly_ &&
      !wallFileOf(node->id()).empty()) {
    // A node that uses a wall file (a display wall) opens as the wall.
    openWall(node->id());
    event->accept();
    return;
  }
  if (event->button() == Qt::LeftButton && node != nullptr && node->kind() == NodeKind::Instance &&
      !readOnly_) {
    openComposite(node->id());
    event->accept();
    return;
  }
  QGraphicsView::mouseDoubleClickEvent(event);
}

bool Canvas::openComposite(const std::string& id) {
  if (state_.app == nullptr) return false;
  auto inside = compositeInside(*state_.app, id);
  const app::Instance* instance = app::findInstance(*state_.app, id);
  if (!inside || instance == nullptr) {
    lastRefusal_ = inside ? QString("no composite instance '%1'").arg(qtText(id))
                          : "Cannot open '" + qtText(id) + "': " + qtText(inside.error().message);
    Q_EMIT messageRequested(lastRefusal_);
    return false;
  }
  closeComposite();
  QStringList in, out;
  for (const auto& port : nodePorts(*state_.app, *state_.catalog, id))
    (port.isInput ? in : out) << qtText(port.name);
  QString path = qtText(state_.app->name.empty() ? std::string("application") : state_.app->name) +
                 "  \u203A  " + qtText(id) + " (composite " + qtText(instance->composite) + ")";
  if (!in.isEmpty()) path += "   inputs: " + in.join(", ");
  if (!out.isEmpty()) path += "   outputs: " + out.join(", ");
  compositeView_ = new CompositeView(this, std::move(*inside), *state_.catalog, path);
  connect(compositeView_, &CompositeView::closeRequested, this, &Canvas::closeComposite);
  return true;
}

void Canvas::closeComposite() {
  if (compositeView_ == nullptr) return;
  compositeView_->hide();
  compositeView_->deleteLater();
  compositeView_ = nullptr;
  setFocus();
}

}  // namespace vrflow::editor::gui
