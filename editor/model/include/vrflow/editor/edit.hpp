#pragma once

// The editor's model layer, without Qt: edits of an application (each one an undoable
// command), port compatibility, host assignment, copy and paste as XML.

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"

namespace vrflow::editor {

/// An undoable edit: the application before and after. The editor's QUndoStack and History
/// below both run these.
struct Edit {
  std::string label;
  app::Application before;
  app::Application after;

  void redo(app::Application& app) const { app = after; }
  void undo(app::Application& app) const { app = before; }
};

/// A linear undo history of edits over one application (what QUndoStack does in the window).
class History {
 public:
  explicit History(app::Application app = {}) : app_(std::move(app)) {}

  const app::Application& application() const { return app_; }
  /// Applies an edit made from application(); drops the edits that were undone.
  void push(Edit edit);
  bool canUndo() const { return index_ > 0; }
  bool canRedo() const { return index_ < edits_.size(); }
  /// Undoes the last edit; false when there is none.
  bool undo();
  /// Redoes the last undone edit; false when there is none.
  bool redo();
  /// True when the application differs from the one last marked clean.
  bool modified() const { return index_ != clean_; }
  void markClean() { clean_ = index_; }
  /// The label of the edit undo() would undo, or empty.
  std::string undoLabel() const { return canUndo() ? edits_[index_ - 1].label : std::string(); }

 private:
  app::Application app_;
  std::vector<Edit> edits_;
  std::size_t index_ = 0;
  std::size_t clean_ = 0;
};

/// What kind of node an id names.
enum class NodeKind { None, Module, Filter, Instance };

/// The kind of node `id` is in `app`.
NodeKind nodeKind(const app::Application& app, std::string_view id);
/// Ids of every module, filter and composite instance, in that order.
std::vector<std::string> nodeIds(const app::Application& app);
/// The ports of a module, filter or instance (instances: the composite's exposed ports, data
/// "any", when the composite is found in the file or beside it; else none).
std::vector<app::PortSpec> nodePorts(const app::Application& app, const app::Catalog& catalog,
                                     std::string_view id);
/// `base` when no node has that id, else base2, base3, ...
std::string uniqueId(const app::Application& app, std::string_view base);

/// Why a connection from output `from` to input `to` is refused (unknown node or port, wrong
/// direction, data types that differ, stamps-only into a full input, a connection already
/// there), or nullopt when it may be made. Same rules as `vrflow validate` for one connection.
std::optional<std::string> connectionRefusal(const app::Application& app,
                                             const app::Catalog& catalog, const app::Endpoint& from,
                                             const app::Endpoint& to);

/// Edits. Each returns the edit (label, before, after) or why it cannot be made.
Result<Edit> addModule(const app::Application& app, const app::Catalog& catalog,
                       std::string_view package, std::string_view type, double x, double y,
                       std::string* newId = nullptr);
Result<Edit> addFilter(const app::Application& app, const app::Catalog& catalog,
                       std::string_view type, double x, double y, std::string* newId = nullptr);
/// Removes nodes with their connections, input settings and positions.
Result<Edit> removeNodes(const app::Application& app, const std::vector<std::string>& ids);
Result<Edit> connect(const app::Application& app, const app::Catalog& catalog,
                     const app::Endpoint& from, const app::Endpoint& to);
/// Removes connections by index in app.connections.
Result<Edit> disconnect(const app::Application& app, std::vector<std::size_t> indexes);
/// Sets a parameter of a module, filter or instance; an empty value removes it (the default).
Result<Edit> setParameter(const app::Application& app, std::string_view node, std::string_view name,
                          std::string value);
/// Renames a parameter set on a node (a misspelt one), keeping its value, place and comments.
Result<Edit> renameParameter(const app::Application& app, std::string_view node,
                             std::string_view name, std::string_view newName);
/// Sets the initial message count of a module's input port (0 removes the setting when the
/// mode is the default).
Result<Edit> setInitialMessages(const app::Application& app, std::string_view module,
                                std::string_view port, int count);
/// Sets the editor position of nodes.
Result<Edit> moveNodes(const app::Application& app,
                       const std::map<std::string, std::pair<double, double>>& positions);
/// Renames a node, following its connections and position.
Result<Edit> renameNode(const app::Application& app, std::string_view id, std::string newId);

/// Hosts.
Result<Edit> assignHost(const app::Application& app, const std::vector<std::string>& nodes,
                        std::string_view host);
Result<Edit> addHost(const app::Application& app, std::string id, std::string address);
/// Removes a host; its nodes go to the first remaining host. The last host cannot be removed.
Result<Edit> removeHost(const app::Application& app, std::string_view id);
/// Renames a host, following the nodes on it.
Result<Edit> renameHost(const app::Application& app, std::string_view id, std::string newId);
Result<Edit> setHostAddress(const app::Application& app, std::string_view id, std::string address);
/// Adds the hosts of a hostfile: one host per line, "NAME [ADDRESS]" or MPI style
/// "NAME slots=N"; '#' starts a comment. Hosts already there get the address given.
Result<Edit> importHostfile(const app::Application& app, std::string_view text);

/// The nodes `ids`, the connections among them and their positions, as application XML (what
/// the editor puts on the clipboard).
std::string copyAsXml(const app::Application& app, const std::vector<std::string>& ids);
/// Pastes what copyAsXml() made: nodes get fresh ids when theirs are taken, positions move by
/// (dx, dy), hosts unknown here become the first host. Fails on text that is not such XML.
Result<Edit> pasteXml(const app::Application& app, std::string_view xml, double dx, double dy,
                      std::vector<std::string>* pastedIds = nullptr);

/// A file as opened: its bytes and the canonical text of what was loaded from them.
struct OpenedText {
  std::string text;
  std::string canonical;  ///< app::saveApplication() of the application loaded from `text`
};

/// What saving `app` writes: the writer's canonical text, except when the application is the
/// one loaded from `opened` (nothing changed, or every change undone): then the file's own bytes,
/// comments and explicit defaults included, so that saving an unchanged file changes nothing.
std::string textToSave(const app::Application& app, const OpenedText& opened);

}  // namespace vrflow::editor
