#pragma once

// A display wall as the lab sees it, opened over the canvas from the node that uses the wall file
// (an instance of the display_wall composite, or a viewer module with `wall`): each tile where it
// hangs on the wall, with its id, host, X display and pixels, the mullions between them.

#include <map>
#include <string>

#include "canvas_overlay.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/viewer/wall.hpp"

class QGraphicsRectItem;
class QGraphicsView;

namespace vrflow::editor::gui {

class WallView : public CanvasOverlay {
  Q_OBJECT

 public:
  /// Shows `wall` over `parent`, which it covers while open; `app` gives the tiles' hosts their
  /// colours and addresses; `path` is the bar's text ("APPLICATION › NODE (wall FILE: ...)").
  WallView(QWidget* parent, viewer::Wall wall, const app::Application& app, const QString& path);

  /// "COLS x ROWS tiles of W x H m, mullions B": the wall in a few words.
  static QString describe(const viewer::Wall& wall);
  QGraphicsView* view() const { return view_; }
  const viewer::Wall& wall() const { return wall_; }
  /// The rectangle drawn for tile `id` (scene units: millimetres of the wall), or nullptr.
  QGraphicsRectItem* tileItem(const std::string& id) const;
  /// The text shown on tile `id` (id, host and address, display, pixels, window).
  QString tileText(const std::string& id) const;

 protected:
  void resizeEvent(QResizeEvent* event) override;

 private:
  void build(const app::Application& app);

  viewer::Wall wall_;
  QGraphicsView* view_;
  std::map<std::string, QGraphicsRectItem*> tiles_;
  std::map<std::string, QString> texts_;
};

}  // namespace vrflow::editor::gui
