#include "main_window.hpp"

#include <QAction>
#include <QApplication>
#include <QClipboard>
#include <QCloseEvent>
#include <QDir>
#include <QDockWidget>
#include <QFile>
#include <QFileInfo>
#include <QLabel>
#include <QListWidget>
#include <QMenu>
#include <QMenuBar>
#include <QPlainTextEdit>
#include <QRegularExpression>
#include <QSaveFile>
#include <QStatusBar>
#include <QToolBar>
#include <QUndoCommand>
#include <QUndoStack>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "log_view.hpp"
#include "qt_text.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/daemon/plugin.hpp"
#include "vrflow/editor/structure_edit.hpp"
#include "vrflow/run/prepare.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::editor::gui {

namespace {

// One edit on the undo stack.
class EditCommand : public QUndoCommand {
 public:
  EditCommand(MainWindow* window, Edit edit)
      : QUndoCommand(qtText(edit.label)), window_(window), edit_(std::move(edit)) {}
  void redo() override {
    edit_.redo(window_->mutableApplication());
    window_->applicationChanged();
  }
  void undo() override {
    edit_.undo(window_->mutableApplication());
    window_->applicationChanged();
  }

 private:
  MainWindow* window_;
  Edit edit_;
};

// Where pasted nodes land: at the cursor when it is over the canvas, else (nullopt) beside the
// copied nodes.
std::optional<std::pair<double, double>> pasteCorner(const Canvas& canvas) {
  const auto at = canvas.cursorScenePos();
  if (!at) return std::nullopt;
  return std::make_pair(std::round(at->x() / 10) * 10, std::round(at->y() / 10) * 10);
}

}  // namespace

// ---- MainWindow --------------------------------------------------------------------------

MainWindow::MainWindow(EditorOptions options, QWidget* parent)
    : QMainWindow(parent),
      options_(std::move(options)),
      reporter_(options_.reporter),
      undo_(new QUndoStack(this)),
      canvas_(new Canvas),
      palette_(new Palette),
      properties_(new PropertiesPanel),
      hosts_(new HostsPanel),
      problemList_(new QListWidget),
      log_(new QPlainTextEdit),
      runs_(new RunController(options_.vrflowProgram.isEmpty()
                                  ? QCoreApplication::applicationDirPath() + "/vrflow"
                                  : options_.vrflowProgram,
                              this)),
      runStatus_(new QLabel),
      moduleLog_(new LogView) {
  if (reporter_ == nullptr) {
    ownReporter_ = std::make_unique<Reporter>();
    reporter_ = ownReporter_.get();
  }
  settings_ = options_.settingsFile.isEmpty()
                  ? std::make_unique<QSettings>("vrflow", "editor")
                  : std::make_unique<QSettings>(options_.settingsFile, QSettings::IniFormat);
  auto catalog = run::loadCatalog(options_.packageDirs);
  if (catalog) {
    catalog_ = std::make_unique<app::Catalog>(std::move(*catalog));
  } else {
    catalog_ = std::make_unique<app::Catalog>(daemon::makeCatalog());
    catalogProblems_ = qtText(catalog.error().message);
  }

  setCentralWidget(canvas_);
  auto dock = [this](const QString& title, QWidget* widget, Qt::DockWidgetArea area) {
    auto* d = new QDockWidget(title, this);
    d->setObjectName(title);
    d->setWidget(widget);
    addDockWidget(area, d);
    return d;
  };
  paletteDock_ = dock("Palette", palette_, Qt::LeftDockWidgetArea);
  propertiesDock_ = dock("Properties", properties_, Qt::RightDockWidgetArea);
  hostsDock_ = dock("Hosts", hosts_, Qt::RightDockWidgetArea);
  splitDockWidget(propertiesDock_, hostsDock_, Qt::Vertical);
  auto* problemsDock = dock("Problems", problemList_, Qt::BottomDockWidgetArea);
  auto* logDock = dock("Run log", log_, Qt::BottomDockWidgetArea);
  tabifyDockWidget(problemsDock, logDock);
  moduleLogDock_ = dock("Module log", moduleLog_, Qt::BottomDockWidgetArea);
  tabifyDockWidget(logDock, moduleLogDock_);
  problemsDock->raise();
  resizeDocks({problemsDock}, {150}, Qt::Vertical);
  log_->setReadOnly(true);
  log_->setMaximumBlockCount(20000);
  QFont mono("monospace");
  mono.setStyleHint(QFont::Monospace);
  log_->setFont(mono);
  palette_->setCatalog(*catalog_);

  connect(canvas_, &Canvas::connectRequested, this,
          [this](const app::Endpoint& from, const app::Endpoint& to) { connectPorts(from, to); });
  connect(canvas_, &Canvas::nodesMoved, this, [this](const Positions& positions) {
    if (!apply(moveNodes(app_, positions))) refresh();
  });
  connect(canvas_, &Canvas::addRequested, this,
          [this](const QString& spec, QPointF at) { addNode(spec, at); });
  connect(canvas_, &Canvas::hostDropped, this,
          [this](const QString& host, const std::string& node) {
            apply(assignHost(app_, {node}, stdText(host)));
          });
  connect(canvas_, &Canvas::deleteRequested, this, &MainWindow::deleteSelection);
  connect(canvas_, &Canvas::editRequested, this,
          [this](const Edit& edit, const std::vector<std::string>& select) {
            // Notes and frames edited on the canvas select nothing new.
            if (apply(edit, select.empty()) && !select.empty()) canvas_->selectOnly(select);
          });
  connect(canvas_, &Canvas::messageRequested, this,
          [this](const QString& text) { statusBar()->showMessage(text, 8000); });
  connect(canvas_, &Canvas::selectionChangedIds, this, &MainWindow::showSelection);
  connect(canvas_, &Canvas::contextMenuForNodes, this,
          [this](const std::vector<std::string>& ids, QPoint at) {
            QMenu menu;
            QMenu* hostsMenu = menu.addMenu("Run on host");
            for (const auto& h : app_.hosts) {
              const std::string id = h.id;
              hostsMenu->addAction(qtText(id), this,
                                   [this, ids, id] { apply(assignHost(app_, ids, id)); });
            }
            if (ids.size() == 1) {
              const std::string id = ids.front();
              menu.addAction("Show log", this, [this, id] { showModuleLog(id); })
                  ->setEnabled(!runs_->runId().isEmpty());
            }
            menu.addAction("Duplicate", this, &MainWindow::duplicateSelection);
            if (ids.size() == 1 && !canvas_->wallFileOf(ids.front()).empty()) {
              menu.addAction("Show wall", this,
                             [this, id = ids.front()] { canvas_->openWall(id); });
            }
            if (ids.size() == 1 && nodeKind(app_, ids.front()) == NodeKind::Instance) {
              menu.addAction("Open composite", this,
                             [this, id = ids.front()] { canvas_->openComposite(id); });
            }
            menu.addAction("Collapse into composite", canvas_, &Canvas::collapseSelection);
            menu.addAction("Copy", this, &MainWindow::copySelection);
            menu.addAction("Delete", this, &MainWindow::deleteSelection);
            menu.exec(at);
          });
  connect(palette_, &Palette::addRequested, this,
          [this](const QString& spec) { addNode(spec, canvas_->dropPoint()); });
  connect(properties_, &PropertiesPanel::parameterEdited, this,
          [this](const std::string& node, const std::string& name, const std::string& value) {
            apply(setParameter(app_, node, name, value));
          });
  connect(properties_, &PropertiesPanel::initialMessagesEdited, this,
          [this](const std::string& node, const std::string& port, int count) {
            apply(setInitialMessages(app_, node, port, count));
          });
  connect(properties_, &PropertiesPanel::hostChosen, this,
          [this](const std::string& node, const std::string& host) {
            apply(assignHost(app_, {node}, host));
          });
  connect(properties_, &PropertiesPanel::renameRequested, this,
          [this](const std::string& node, const std::string& newId) {
            if (apply(renameNode(app_, node, newId), false)) canvas_->selectOnly({newId});
          });
  connect(hosts_, &HostsPanel::addRequested, this, [this] {
    QString id = QString("host%1").arg(app_.hosts.size() + 1);
    QString address = "127.0.0.1";
    if (reporter().newHost(this, id, address))
      apply(addHost(app_, stdText(id), stdText(address)), false);
  });
  connect(hosts_, &HostsPanel::removeRequested, this,
          [this](const std::string& host) { apply(removeHost(app_, host), false); });
  connect(hosts_, &HostsPanel::renameRequested, this,
          [this](const std::string& host, const std::string& newId) {
            if (!apply(renameHost(app_, host, newId), false)) hosts_->show(app_);
          });
  connect(hosts_, &HostsPanel::addressChanged, this,
          [this](const std::string& host, const std::string& address) {
            if (!apply(setHostAddress(app_, host, address), false)) hosts_->show(app_);
          });
  connect(hosts_, &HostsPanel::importRequested, this, [this] {
    const QString file = reporter().hostfileName(this, QDir::homePath());
    if (file.isEmpty()) return;
    QFile in(file);
    if (!in.open(QIODevice::ReadOnly)) {
      reporter().error(this, "Import hosts", "Cannot read " + file + ": " + in.errorString());
      return;
    }
    apply(importHostfile(app_, in.readAll().toStdString()), false);
  });
  connect(hosts_, &HostsPanel::assignSelectionRequested, this, &MainWindow::assignSelectionToHost);
  connect(problemList_, &QListWidget::itemActivated, this,
          [this](QListWidgetItem* item) { problemActivated(problemList_->row(item)); });
  connect(undo_, &QUndoStack::cleanChanged, this, &MainWindow::updateTitle);

  buildMenus();
  resize(1400, 860);
  newFile();
  if (!catalogProblems_.isEmpty()) log_->appendPlainText("Node packages: " + catalogProblems_);
  log_->appendPlainText(QString("%1 module types and %2 filter types from: %3")
                            .arg(catalog_->moduleTypes().size())
                            .arg(catalog_->filterTypes().size())
                            .arg(catalog_->manifestFiles().empty()
                                     ? QString("(no package found)")
                                     : qtText(catalog_->manifestFiles().front()) +
                                           (catalog_->manifestFiles().size() > 1 ? ", ..." : "")));
}

MainWindow::~MainWindow() {
  runs_->disconnect(this);
  runs_->live()->disconnect(this);
  // The panels outlive this object's members (Qt deletes children last): no more signals here.
  for (QObject* child : std::initializer_list<QObject*>{canvas_, palette_, properties_, hosts_,
                                                        problemList_, undo_}) {
    child->disconnect(this);
    disconnect(child, nullptr, this, nullptr);
  }
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu("&File");
  file->addAction("&New", QKeySequence::New, this, [this] {
    if (maybeSave()) newFile();
  });
  file->addAction("&Open\u2026", QKeySequence::Open, this, [this] {
    if (!maybeSave()) return;
    const QString path = reporter().fileName(
        this, false, path_.isEmpty() ? QDir::currentPath() : QFileInfo(path_).path());
    if (!path.isEmpty()) openFile(path);
  });
  recentMenu_ = file->addMenu("Open &recent");
  file->addAction("&Save", QKeySequence::Save, this, [this] { save(); });
  file->addAction("Save &as\u2026", QKeySequence::SaveAs, this, [this] {
    const QString path = reporter().fileName(this, true, path_);
    if (!path.isEmpty()) saveAs(path);
  });
  file->addSeparator();
  file->addAction("&Quit", QKeySequence::Quit, this, &QWidget::close);
  rebuildRecentMenu();

  QMenu* edit = menuBar()->addMenu("&Edit");
  QAction* undo = undo_->createUndoAction(this, "&Undo");
  undo->setShortcut(QKeySequence::Undo);
  QAction* redo = undo_->createRedoAction(this, "&Redo");
  redo->setShortcut(QKeySequence::Redo);
  edit->addAction(undo);
  edit->addAction(redo);
  edit->addSeparator();
  edit->addAction("&Copy", QKeySequence::Copy, this, &MainWindow::copySelection);
  edit->addAction("&Paste", QKeySequence::Paste, this, &MainWindow::paste);
  edit->addAction("&Duplicate", QKeySequence(Qt::CTRL | Qt::Key_D), this,
                  &MainWindow::duplicateSelection);
  edit->addAction("De&lete", QKeySequence::Delete, this, &MainWindow::deleteSelection);
  edit->addAction("Select &all", QKeySequence::SelectAll, this,
                  [this] { canvas_->selectOnly(nodeIds(app_)); });

  QMenu* view = menuBar()->addMenu("&View");
  view->addAction("&Automatic layout", QKeySequence(Qt::CTRL | Qt::Key_L), this,
                  &MainWindow::autoLayout);
  view->addAction("&Fit all", QKeySequence(Qt::CTRL | Qt::Key_0), canvas_, &Canvas::fitAll);
  view->addAction("Zoom &in", QKeySequence::ZoomIn, this, [this] { canvas_->scale(1.2, 1.2); });
  view->addAction("Zoom &out", QKeySequence::ZoomOut, this,
                  [this] { canvas_->scale(1 / 1.2, 1 / 1.2); });

  QMenu* runMenu = setUpRuns();

  QToolBar* tools = addToolBar("Main");
  tools->setObjectName("Main");
  tools->addAction(undo);
  tools->addAction(redo);
  tools->addSeparator();
  tools->addAction("Layout", this, &MainWindow::autoLayout);
  tools->addAction("Fit", canvas_, &Canvas::fitAll);
  tools->addSeparator();
  tools->addAction(runAction_);
  tools->addAction(launchAction_);
  tools->addAction(stopAction_);
  setUpLiveView(runMenu);  // the live overlay, run table and timeline (main_window_live.cpp)
}

// ---- State -------------------------------------------------------------------------------

void MainWindow::computeFallbackLayout() {
  canvas_->state().fallback.clear();
  std::vector<std::string> missing;
  for (const auto& id : nodeIds(app_)) {
    if (app::findEditorNode(app_, id) == nullptr) missing.push_back(id);
  }
  if (missing.empty()) return;
  canvas_->state().app = &app_;
  canvas_->state().catalog = catalog_.get();
  canvas_->rebuild();
  auto layout = editor::autoLayout(app_, canvas_->nodeSizes());
  // Below the nodes the file places, when there are some.
  double shift = 0;
  bool placed = false;
  double bottom = 0;
  for (const auto& n : app_.editor) {
    bottom = placed ? std::max(bottom, n.y) : n.y;
    placed = true;
  }
  if (placed) {
    double top = 0;
    bool first = true;
    for (const auto& id : missing) {
      top = first ? layout[id].second : std::min(top, layout[id].second);
      first = false;
    }
    shift = bottom + 200 - top;
  }
  for (const auto& id : missing) {
    canvas_->state().fallback[id] = {layout[id].first, layout[id].second + shift};
  }
}

void MainWindow::applicationChanged() {
  if (!path_.isEmpty()) app_.file = stdText(path_);
  refresh();
}

void MainWindow::refresh() {
  const std::size_t filterTypes = catalog_->filterTypes().size();
  problems_ = findProblems(
      app_, *catalog_,
      [this](const app::Application& loaded) {
        return daemon::loadApplicationPlugins(loaded, *catalog_);
      },
      &opened_);
  if (catalog_->filterTypes().size() != filterTypes)
    palette_->setCatalog(*catalog_);  // a plugin added some
  CanvasState& state = canvas_->state();
  state.app = &app_;
  state.catalog = catalog_.get();
  state.problems = problems_;
  state.run = lastRun_;
  canvas_->sync();  // only what changed since the scene last showed the application
  hosts_->show(app_);

  problemList_->clear();
  int errors = 0, warnings = 0;
  for (const auto& p : problems_) {
    const bool error = p.severity == app::Diagnostic::Error;
    (error ? errors : warnings) += 1;
    QString where = qtText(p.node);
    if (p.connection && *p.connection < app_.connections.size()) {
      const auto& c = app_.connections[*p.connection];
      where = qtText(app::toString(c.from) + " \u2192 " + app::toString(c.to));
    }
    if (!p.cycle.empty()) where = "deadlock";
    auto* item = new QListWidgetItem(
        style()->standardIcon(error ? QStyle::SP_MessageBoxCritical : QStyle::SP_MessageBoxWarning),
        (where.isEmpty() ? QString() : where + ": ") + qtText(p.message));
    item->setToolTip(qtText(p.text));
    if (const auto fix = parameterSuggestion(p)) {
      item->setText(item->text() + "  \u2014 double-click to rename it to '" + qtText(fix->second) +
                    "'");
    }
    problemList_->addItem(item);
  }
  statusBar()->showMessage(errors + warnings == 0
                               ? QString("Valid: %1 modules, %2 filters, %3 connections")
                                     .arg(app_.modules.size())
                                     .arg(app_.filters.size())
                                     .arg(app_.connections.size())
                               : QString("%1 errors, %2 warnings").arg(errors).arg(warnings));
  showSelection();
  updateTitle();
}

void MainWindow::showSelection() {
  const auto selected = canvas_->selectedNodes();
  properties_->show(app_, *catalog_, selected.size() == 1 ? selected.front() : std::string());
}

// A parameter the node's type does not declare, and the declared name validation suggests:
// "... has no parameter 'stifness' (parameters: ...); did you mean 'stiffness'?".
std::optional<std::pair<std::string, std::string>> MainWindow::parameterSuggestion(
    const Problem& problem) {
  static const QRegularExpression pattern(
      "has no parameter '([^']+)' .*did you mean '([^']+)'\\?$");
  if (problem.node.empty()) return std::nullopt;
  const QRegularExpressionMatch match = pattern.match(qtText(problem.message));
  if (!match.hasMatch()) return std::nullopt;
  return std::make_pair(stdText(match.captured(1)), stdText(match.captured(2)));
}

void MainWindow::problemActivated(int row) {
  if (row < 0 || static_cast<std::size_t>(row) >= problems_.size()) return;
  const Problem& p = problems_[static_cast<std::size_t>(row)];
  std::vector<std::string> nodes;
  if (!p.node.empty()) nodes.push_back(p.node);
  for (std::size_t c : p.cycle) {
    if (c < app_.connections.size()) nodes.push_back(app_.connections[c].from.node);
  }
  std::optional<std::size_t> connection = p.connection;
  if (!p.cycle.empty()) connection = p.cycle.front();
  canvas_->selectOnly(nodes, connection);
  // A misspelt parameter with a suggestion: the double-click renames it (one undoable edit).
  // Queued: the edit refills the list, which must not happen inside its own signal.
  if (const auto fix = parameterSuggestion(p)) {
    QMetaObject::invokeMethod(
        this,
        [this, node = p.node, from = fix->first, to = fix->second] {
          apply(renameParameter(app_, node, from, to), false);
        },
        Qt::QueuedConnection);
  }
}

// ---- Edits -------------------------------------------------------------------------------

bool MainWindow::apply(Result<Edit> edit, bool quietWhenUnchanged) {
  if (!edit) {
    const QString why = qtText(edit.error().message);
    if (!(quietWhenUnchanged && why == "unchanged")) statusBar()->showMessage(why, 8000);
    return false;
  }
  undo_->push(new EditCommand(this, std::move(*edit)));
  return true;
}

bool MainWindow::addNode(const QString& spec, QPointF at) {
  const QStringList parts = spec.split(' ', Qt::SkipEmptyParts);
  std::string id;
  bool ok = false;
  if (parts.size() == 3 && parts[0] == "module") {
    ok =
        apply(addModule(app_, *catalog_, stdText(parts[1]), stdText(parts[2]), at.x(), at.y(), &id),
              false);
  } else if (parts.size() == 2 && parts[0] == "filter") {
    ok = apply(addFilter(app_, *catalog_, stdText(parts[1]), at.x(), at.y(), &id), false);
  }
  if (ok) canvas_->selectOnly({id});
  return ok;
}

bool MainWindow::connectPorts(const app::Endpoint& from, const app::Endpoint& to) {
  return apply(editor::connect(app_, *catalog_, from, to), false);
}

void MainWindow::deleteSelection() {
  const auto nodes = canvas_->selectedNodes();
  const auto connections = canvas_->selectedConnections();
  if (nodes.empty() && connections.empty()) return;
  Edit edit{"", app_, app_};
  if (!connections.empty()) {
    auto step = editor::disconnect(edit.after, connections);
    if (step) {
      edit.after = step->after;
      edit.label = step->label;
    }
  }
  if (!nodes.empty()) {
    auto step = removeNodes(edit.after, nodes);
    if (step) {
      edit.after = step->after;
      edit.label = step->label;
    }
  }
  if (!nodes.empty() && !connections.empty()) edit.label = "Delete selection";
  apply(std::move(edit));
}

void MainWindow::copySelection() {
  const auto nodes = canvas_->selectedNodes();
  if (nodes.empty()) return;
  QApplication::clipboard()->setText(qtText(copyAsXml(app_, nodes)));
  statusBar()->showMessage(QString("Copied %1 nodes as XML").arg(nodes.size()), 4000);
}

void MainWindow::paste() {
  const auto corner = pasteCorner(*canvas_);
  std::vector<std::string> ids;
  if (apply(pasteXmlAt(app_, stdText(QApplication::clipboard()->text()), corner, &ids), false))
    canvas_->selectOnly(ids);
}

void MainWindow::duplicateSelection() {
  const auto nodes = canvas_->selectedNodes();
  if (nodes.empty()) return;
  const auto corner = pasteCorner(*canvas_);
  std::vector<std::string> ids;
  auto edit = pasteXmlAt(app_, copyAsXml(app_, nodes), corner, &ids);
  if (edit) edit->label = "Duplicate";
  if (apply(std::move(edit), false)) canvas_->selectOnly(ids);
}

void MainWindow::autoLayout() {
  auto edit = moveNodes(app_, editor::autoLayout(app_, canvas_->nodeSizes()));
  if (edit) edit->label = "Automatic layout";
  apply(std::move(edit));
  canvas_->fitAll();
}

void MainWindow::assignSelectionToHost(const std::string& host) {
  const auto nodes = canvas_->selectedNodes();
  if (nodes.empty()) {
    statusBar()->showMessage("Select nodes first", 4000);
    return;
  }
  apply(assignHost(app_, nodes, host));
}

bool MainWindow::screenshot(const QString& path) {
  QApplication::processEvents();
  const QPixmap pixmap = grab();
  return !pixmap.isNull() && pixmap.save(path, "PNG");
}

}  // namespace vrflow::editor::gui
