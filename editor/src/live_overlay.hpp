#pragma once

// The live view of a run on the canvas (docs/editor.md, "Live view"): a badge under each module,
// a load band and rate label on each connection, a band between hosts that exchange messages,
// red outlines with their cause on failed modules and lost hosts. Its items are children of the
// canvas' items (or scene items of their own); a canvas rebuild that deletes them is noticed
// (QPointer) and they are made again from the LiveRun.

#include <QObject>
#include <QPointer>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "connection_load_item.hpp"
#include "link_item.hpp"
#include "live_run.hpp"
#include "module_badge_item.hpp"

namespace vrflow::editor::gui {

class Canvas;

/// The canvas node that shows `module` of the expanded network (itself, or the composite
/// instance it belongs to), or empty when the canvas has none.
std::string canvasNodeOf(const Canvas& canvas, const std::string& module);

/// Keeps the canvas' live items in step with a LiveRunModel.
class LiveOverlay : public QObject {
  Q_OBJECT

 public:
  LiveOverlay(Canvas* canvas, LiveRunModel* model, QObject* parent = nullptr);
  /// Makes, updates or removes the items from the model's run.
  void refresh();
  /// The badge under a canvas node, or nullptr.
  ModuleBadgeItem* badge(const std::string& node) const;
  /// The load item of canvas connection `index`, or nullptr.
  ConnectionLoadItem* connectionLoad(std::size_t index) const;
  /// The bands between hosts.
  std::vector<LinkItem*> links() const;

 private:
  void clear();
  void sceneChanged();
  void refreshModules(const LiveRun& run);
  void refreshConnections(const LiveRun& run);
  void refreshLinks(const LiveRun& run);

  QPointer<Canvas> canvas_;
  QPointer<LiveRunModel> model_;
  std::map<std::string, QPointer<ModuleBadgeItem>> badges_;
  std::map<std::size_t, QPointer<ConnectionLoadItem>> loads_;
  std::map<std::pair<std::string, std::string>, QPointer<LinkItem>> links_;
  bool pending_ = false;
};

}  // namespace vrflow::editor::gui
