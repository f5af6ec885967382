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

#include "canvas_style.hpp"
#include "connection_item.hpp"
#include "frame_item.hpp"
#include "node_item.hpp"
#include "note_item.hpp"
#include "port_item.hpp"
#include "routing.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/editor/analysis.hpp"
#include "vrflow/editor/changes.hpp"
#include "vrflow/editor/edit.hpp"

class QGraphicsScene;
class QGraphicsPathItem;
class QMenu;

namespace vrflow::editor::gui {

/// Node positions by id (top-left corner, scene units).
using Positions = std::map<std::string, std::pair<double, double>>;

/// Mime type of palette entries: "module PACKAGE TYPE" or "filter TYPE".
inline constexpr const char* kNodeMime = "application/x-vrflow-node";
/// Mime type of a host dragged from the hosts panel: its id.
inline constexpr const char* kHostMime = "application/x-vrflow-host";

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

class QuickAdd;
class CompositeView;
class WallView;

class Canvas : public QGraphicsView {
  Q_OBJECT

 public:
  explicit Canvas(QWidget* parent = nullptr);
  ~Canvas() override;

  CanvasState& state() { return state_; }
  /// Recreates every item from state(); keeps the selection (by id) and the view.
  void rebuild();
  /// Brings the scene up to date with state() by what changed since the last rebuild() or
  /// sync() (editor::diff()): only the items of added, removed or changed nodes, connections,
  /// notes and frames are created or deleted; the others stay (with their selection, a drag in
  /// progress and the view), moved or redrawn in place.
  void sync();

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
  /// The item of a note, or nullptr.
  NoteItem* noteItem(const std::string& id) const;
  /// The item of a frame, or nullptr.
  FrameItem* frameItem(const std::string& id) const;
  /// The selected notes' and frames' ids.
  std::vector<std::string> selectedNotesAndFrames() const;
  /// The menu a right-click at `viewPos` opens on a frame or on empty canvas (add a note, a
  /// frame, a frame around the selection; rename, recolour, delete a frame), or nullptr over
  /// a node (contextMenuForNodes() is emitted then). The caller owns it.
  QMenu* contextMenuAt(QPoint viewPos);
  /// Scene position of a port's connection point.
  QPointF portScenePos(const std::string& node, const std::string& port) const;
  /// Shows live iterations/s on the nodes, in place (no rebuild: a drag in progress goes on).
  void setLiveRates(const std::map<std::string, double>& rates);
  /// Shows every node, note and frame: zooms out as far as they need, in no further than 1x.
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
  bool event(QEvent* event) override;
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
  FrameItem* frameAt(QPoint viewPos) const;

  // canvas_scene.cpp: nodes and connections.
  NodeItem* makeNode(const std::string& id);
  void placeNode(NodeItem* item);
  void removeNode(const std::string& id);
  void syncConnections();
  void routeConnections();
  void decorate();
  // canvas_notes.cpp: notes and frames.
  void syncNotesAndFrames();
  void reportNoteAndFrameChanges();
  void requestEdit(Result<Edit> edit);
  void addFrameAroundSelection();
  QMenu* frameMenu(FrameItem* frame);

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
  /// The wall file node `id` uses (its `wall` parameter: a display_wall instance or a viewer
  /// module), resolved beside the application file; empty when it has none.
  std::string wallFileOf(const std::string& id) const;
  /// Shows the wall of node `id` over the canvas, its tiles where they hang; false with the
  /// reason in lastRefusal() when the node has no wall or its file cannot be read.
  bool openWall(const std::string& id);
  /// The open wall's view, or nullptr.
  WallView* wallView() const { return wallView_; }
  /// A read-only canvas (an opened composite's inside) shows and offers no edit.
  void setReadOnly(bool readOnly);
  /// The connection highlighted as the target of a node drop, or nullopt.
  std::optional<std::size_t> wireUnderDrop() const { return wireHover_; }

 Q_SIGNALS:
  /// An edit made on the canvas (insert, quick-add with a connection, collapse, notes and
  /// frames); `select`: the nodes to select once it is applied (none: the selection stays).
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
  void closeWall();
  void quickAddChosen(const QString& spec);
  std::optional<std::size_t> wireAt(QPoint viewPos, const std::string& node) const;
  void setWireHover(std::optional<std::size_t> index, const std::optional<std::string>& refusal,
                    QPoint at);

  QuickAdd* quickAdd_ = nullptr;
  CompositeView* compositeView_ = nullptr;
  WallView* wallView_ = nullptr;
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
  /// The application as the scene last showed it (what sync() compares against).
  std::optional<app::Application> shown_;
  std::map<std::string, NodeItem*> nodes_;
  /// What each node item was made from (title, ports, host): remade when that differs.
  std::map<std::string, QString> looks_;
  std::vector<ConnectionItem*> connections_;
  std::map<std::string, NoteItem*> notes_;
  std::map<std::string, FrameItem*> frames_;
  std::vector<QGraphicsItem*> decorations_;
  PortItem* dragFrom_ = nullptr;
  QGraphicsPathItem* dragLine_ = nullptr;
  bool panning_ = false;
  QPoint panLast_;
  QString lastRefusal_;
};

}  // namespace vrflow::editor::gui
