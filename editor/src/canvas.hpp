#pragma once

// The canvas: modules as boxes, filters as rhombi, composite instances as dashed boxes,
// connections as curves coloured by message type; drag from port to port to connect.

#include <QColor>
#include <QGraphicsItem>
#include <QGraphicsView>
#include <QPainterPath>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/editor/analysis.hpp"
#include "vrflow/editor/edit.hpp"

class QGraphicsScene;
class QGraphicsPathItem;

namespace vrflow::editor::gui {

/// Node positions by id (top-left corner, scene units).
using Positions = std::map<std::string, std::pair<double, double>>;

/// Mime type of palette entries: "module PACKAGE TYPE" or "filter TYPE".
inline constexpr const char* kNodeMime = "application/x-vrflow-node";
/// Mime type of a host dragged from the hosts panel: its id.
inline constexpr const char* kHostMime = "application/x-vrflow-host";

/// The colour of a message data type ("objects", "events", ..., "any").
QColor colorOfData(const std::string& data);
/// The colour of the host at `index` in the application's host list.
QColor colorOfHost(std::size_t index);
/// The curve of a connection from an output at `from` to an input at `to` (around, below both
/// ends, when it goes back).
QPainterPath connectionCurve(QPointF from, QPointF to);

/// What the canvas draws, besides the application.
struct CanvasState {
  const app::Application* app = nullptr;
  const app::Catalog* catalog = nullptr;
  std::vector<Problem> problems;
  std::optional<RunReport> run;
  /// Positions for nodes the file places nowhere (shown there, not saved until moved).
  Positions fallback;
  /// Live iterations/s per module while a run goes on (from the runtime's progress line).
  std::map<std::string, double> live;
};

class NodeItem;
class PortItem;
class ConnectionItem;
class QuickAdd;
class CompositeView;

class Canvas : public QGraphicsView {
  Q_OBJECT

 public:
  explicit Canvas(QWidget* parent = nullptr);
  ~Canvas() override;

  CanvasState& state() { return state_; }
  /// Recreates every item from state(); keeps the selection (by id) and the view.
  void rebuild();

  /// The selected nodes' ids (in model order).
  std::vector<std::string> selectedNodes() const;
  /// The selected connections' indexes.
  std::vector<std::size_t> selectedConnections() const;
  /// Selects exactly these nodes (and connection, when given) and shows them.
  void selectOnly(const std::vector<std::string>& ids, std::optional<std::size_t> connection = {});
  /// The item of a node, or nullptr.
  NodeItem* nodeItem(const std::string& id) const;
  /// The item of a port, or nullptr.
  PortItem* portItem(const std::string& node, const std::string& port) const;
  /// The item of connection `index`, or nullptr.
  ConnectionItem* connectionItem(std::size_t index) const;
  /// Scene position of a port's connection point.
  QPointF portScenePos(const std::string& node, const std::string& port) const;
  /// Shows live iterations/s on the nodes, in place (no rebuild: a drag in progress goes on).
  void setLiveRates(const std::map<std::string, double>& rates);
  /// Shows every node.
  void fitAll();
  /// Sizes of the node items (for the automatic layout).
  Positions nodeSizes() const;
  /// Why dropping a drag that started at `from` on `to` would be refused, or nullopt.
  std::optional<std::string> refusalBetween(const PortItem* from, const PortItem* to) const;
  /// The last refusal shown while connecting (empty when the last attempt connected).
  const QString& lastRefusal() const { return lastRefusal_; }
  /// The scene position where a paste or an add lands (the centre of the view).
  QPointF dropPoint() const;

 Q_SIGNALS:
  void connectRequested(const app::Endpoint& from, const app::Endpoint& to);
  void nodesMoved(const Positions& positions);
  void addRequested(const QString& spec, QPointF scenePos);
  void hostDropped(const QString& host, const std::string& node);
  void deleteRequested();
  void selectionChangedIds();
  void contextMenuForNodes(const std::vector<std::string>& ids, QPoint globalPos);

 protected:
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;
  void contextMenuEvent(QContextMenuEvent* event) override;
  void dragEnterEvent(QDragEnterEvent* event) override;
  void dragMoveEvent(QDragMoveEvent* event) override;
  void dropEvent(QDropEvent* event) override;
  void drawBackground(QPainter* painter, const QRectF& rect) override;

 private:
  PortItem* portAt(QPoint viewPos) const;
  NodeItem* nodeAt(QPoint viewPos) const;

  // ---- Interactions (canvas_interactions.cpp): quick-add, wire drops, insert on a wire, the
  // paste point, composites opened and collapsed. ----
 public:
  /// The cursor's scene position when it is over the view (where a paste lands), else nullopt.
  std::optional<QPointF> cursorScenePos() const;
  /// Opens the quick-add popup at view position `at` with `text` typed; with `wireFrom`, it
  /// lists only the types that connect to that port and connects the one chosen.
  void openQuickAdd(QPoint at, const QString& text = {}, const PortItem* wireFrom = nullptr);
  /// The quick-add popup (nullptr before the first use).
  QuickAdd* quickAdd() const { return quickAdd_; }
  /// Collapses the selected nodes into a new composite, one undoable edit (editRequested).
  void collapseSelection();
  /// Opens (drills down into) composite instance `id` over the canvas; false with the reason in
  /// lastRefusal() when its inside cannot be read.
  bool openComposite(const std::string& id);
  /// The open composite's view, or nullptr when the application is shown.
  CompositeView* compositeView() const { return compositeView_; }
  /// A read-only canvas (an opened composite's inside) shows and offers no edit.
  void setReadOnly(bool readOnly);
  /// The connection highlighted as the target of a node drop, or nullopt.
  std::optional<std::size_t> wireUnderDrop() const { return wireHover_; }

 Q_SIGNALS:
  /// An edit made on the canvas (insert, quick-add with a connection, collapse); `select`: the
  /// nodes to select once it is applied.
  void editRequested(const vrflow::editor::Edit& edit, const std::vector<std::string>& select);
  /// Something to say in the status bar (why a drop or an opening was refused).
  void messageRequested(const QString& text);

 protected:
  void mouseDoubleClickEvent(QMouseEvent* event) override;
  bool focusNextPrevChild(bool next) override;
  void dragLeaveEvent(QDragLeaveEvent* event) override;

 private:
  bool quickAddKey(QKeyEvent* event);
  void trackDrag(QMouseEvent* event);
  bool offerNodesForWire(const PortItem* from, QPoint at);
  bool dropSelectionOnWire();
  void hoverWireForSpec(const QString& spec, QPoint at);
  bool dropSpecOnWire(const QString& spec, QPoint at);
  void closeComposite();
  void quickAddChosen(const QString& spec);
  std::optional<std::size_t> wireAt(QPoint viewPos, const std::string& node) const;
  void setWireHover(std::optional<std::size_t> index, const std::optional<std::string>& refusal,
                    QPoint at);

  QuickAdd* quickAdd_ = nullptr;
  CompositeView* compositeView_ = nullptr;
  std::optional<std::size_t> wireHover_;  ///< a connection the drop would accept
  std::optional<std::size_t> wireShown_;  ///< the connection drawn highlighted
  std::optional<app::Endpoint> quickAddWire_;
  bool quickAddWireIsOutput_ = true;
  QPointF quickAddAt_;
  bool readOnly_ = false;
  // ---- end of interactions ----

 private:
  QGraphicsScene* scene_;
  CanvasState state_;
  std::map<std::string, NodeItem*> nodes_;
  std::vector<ConnectionItem*> connections_;
  std::vector<QGraphicsItem*> decorations_;
  PortItem* dragFrom_ = nullptr;
  QGraphicsPathItem* dragLine_ = nullptr;
  bool panning_ = false;
  QPoint panLast_;
  QString lastRefusal_;
};

/// A port: a small circle on its node's edge with its name beside it.
class PortItem : public QGraphicsItem {
 public:
  PortItem(QGraphicsItem* parent, std::string node, app::PortSpec spec);
  QRectF boundingRect() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& node() const { return node_; }
  const app::PortSpec& spec() const { return spec_; }
  app::Endpoint endpoint() const { return {node_, spec_.name}; }
  void setHighlight(int highlight) {  // 0 none, 1 accepts, -1 refuses
    highlight_ = highlight;
    update();
  }
  void setLabelSide(bool left) { labelLeft_ = left; }

 private:
  std::string node_;
  app::PortSpec spec_;
  int highlight_ = 0;
  bool labelLeft_ = false;
};

/// A module (box), filter (rhombus) or composite instance (dashed box).
class NodeItem : public QGraphicsItem {
 public:
  NodeItem(std::string id, NodeKind kind, QString title, QString subtitle, QColor hostColor,
           QString hostName, const std::vector<app::PortSpec>& ports);
  QRectF boundingRect() const override;
  QPainterPath shape() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  const std::string& id() const { return id_; }
  NodeKind kind() const { return kind_; }
  QSizeF size() const { return size_; }
  std::vector<PortItem*> ports() const { return ports_; }
  /// Problems on this node: 0 none, 1 warning, 2 error; the tooltip lists them.
  void setProblems(int level, const QString& text);
  /// Text under the node (run statistics) and whether the run failed here.
  void setRunInfo(const QString& text, bool failed);
  /// Text on the node's badge ("x5 on a, b" for instances), empty for none.
  void setBadge(const QString& text) { badge_ = text; }
  int problemLevel() const { return problemLevel_; }

 private:
  std::string id_;
  NodeKind kind_;
  QString title_;
  QString subtitle_;
  QColor hostColor_;
  QString hostName_;
  QSizeF size_;
  std::vector<PortItem*> ports_;
  int problemLevel_ = 0;
  QString runInfo_;
  QString badge_;
  bool failed_ = false;
};

/// A connection: a cubic curve from an output port to an input port.
class ConnectionItem : public QGraphicsItem {
 public:
  ConnectionItem(std::size_t index, QPointF from, QPointF to, QColor color, bool stampsOnly);
  QRectF boundingRect() const override;
  QPainterPath shape() const override;
  void paint(QPainter* painter, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

  std::size_t index() const { return index_; }
  QColor color() const { return color_; }
  /// 0 fine, 1 warning, 2 error, 3 part of a deadlock cycle.
  void setProblem(int level) {
    problem_ = level;
    update();
  }
  int problem() const { return problem_; }
  void setLabel(const QString& text) { label_ = text; }
  const QString& label() const { return label_; }
  QPointF midPoint() const { return mid_; }

 private:
  std::size_t index_;
  QPainterPath path_;
  QColor color_;
  bool stampsOnly_;
  int problem_ = 0;
  QString label_;
  QPointF mid_;
};

}  // namespace vrflow::editor::gui
