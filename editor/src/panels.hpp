#pragma once

// The docks around the canvas: the palette of node types, the properties of the selected node,
// the cluster's hosts.

#include <QTreeWidget>
#include <QWidget>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"

class QLineEdit;
class QTableWidget;
class QFormLayout;
class QLabel;
class QVBoxLayout;
class QToolButton;

namespace vrflow::editor::gui {

/// The node types of the catalog, grouped (animators, interactors, viewers, inputs, other
/// modules, filters) and searchable; entries are dragged onto the canvas or double-clicked.
class Palette : public QWidget {
  Q_OBJECT

 public:
  explicit Palette(QWidget* parent = nullptr);
  void setCatalog(const app::Catalog& catalog);
  /// Shows only the entries whose name or documentation contains `text`.
  void setFilterText(const QString& text);
  QTreeWidget* tree() const { return tree_; }
  /// The entry for "module PACKAGE TYPE" or "filter TYPE", or nullptr.
  QTreeWidgetItem* findEntry(const QString& spec) const;

 Q_SIGNALS:
  /// Double click: add this node ("module PACKAGE TYPE" or "filter TYPE").
  void addRequested(const QString& spec);

 private:
  QLineEdit* search_;
  QTreeWidget* tree_;
};

/// The palette's tree: its items drag as kNodeMime.
class PaletteTree : public QTreeWidget {
  Q_OBJECT

 public:
  using QTreeWidget::QTreeWidget;

 protected:
  QMimeData* mimeData(const QList<QTreeWidgetItem*>& items) const override;

 public:
  /// What dragging `items` carries (public so that tests can drop it like a drag would).
  QMimeData* dragData(const QList<QTreeWidgetItem*>& items) const { return mimeData(items); }
};

/// The selected node's id, host, parameters (a widget per type, with default and
/// documentation) and, for modules, the initial messages of each input.
class PropertiesPanel : public QWidget {
  Q_OBJECT

 public:
  explicit PropertiesPanel(QWidget* parent = nullptr);
  /// Shows `node` of `app` (nothing when empty).
  void show(const app::Application& app, const app::Catalog& catalog, const std::string& node);
  const std::string& node() const { return node_; }
  /// The editor widget of a parameter (for tests), or nullptr.
  QWidget* parameterWidget(const QString& name) const;
  /// The initial-messages spin box of an input port, or nullptr.
  QWidget* initialMessagesWidget(const QString& port) const;

 Q_SIGNALS:
  void parameterEdited(const std::string& node, const std::string& name, const std::string& value);
  void initialMessagesEdited(const std::string& node, const std::string& port, int count);
  void hostChosen(const std::string& node, const std::string& host);
  void renameRequested(const std::string& node, const std::string& newId);
  /// "Override for this run" on a parameter: pass `node.name=value` to the next run only.
  void overrideForRunRequested(const std::string& node, const std::string& name,
                               const std::string& value);

 private:
  /// The widgets of one parameter and the value they show.
  struct ParamRow {
    std::string shown;  ///< the value set in the file, or the default
    bool set = false;
    std::function<void(const std::string&)> display;  ///< shows a value without emitting
    QLabel* label = nullptr;
    QToolButton* reset = nullptr;
  };

  QWidget* editorFor(const app::ParamSpec& spec, ParamRow& row);
  void addParameterRow(QFormLayout* form, const app::ParamSpec& spec, ParamRow& row, bool declared);
  void build(const app::Application& app, const app::Catalog& catalog);
  void updateInPlace(const app::Application& app, const app::Catalog& catalog);
  void clear();

  std::string node_;
  std::string structure_;  ///< what the widgets were built for; see structureOf()
  std::map<std::string, ParamRow> rows_;
  QVBoxLayout* layout_;
  QWidget* body_ = nullptr;
};

/// The hosts: id, address, colour; add, remove, rename, import a hostfile, assign the
/// selection. A host's row drags onto a node to assign it.
class HostsPanel : public QWidget {
  Q_OBJECT

 public:
  explicit HostsPanel(QWidget* parent = nullptr);
  void show(const app::Application& app);
  QTableWidget* table() const { return table_; }
  /// The host of the current row, or empty.
  std::string currentHost() const;

 Q_SIGNALS:
  void addRequested();
  void removeRequested(const std::string& host);
  void renameRequested(const std::string& host, const std::string& newId);
  void addressChanged(const std::string& host, const std::string& address);
  void importRequested();
  void assignSelectionRequested(const std::string& host);

 private:
  QTableWidget* table_;
  std::vector<std::string> ids_;
  bool filling_ = false;
};

}  // namespace vrflow::editor::gui
