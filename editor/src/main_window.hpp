#pragma once

#include <QMainWindow>
#include <QSettings>
#include <QStringList>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "canvas.hpp"
#include "live_overlay.hpp"
#include "live_run.hpp"
#include "panels.hpp"
#include "run_controller.hpp"
#include "run_table.hpp"
#include "timeline.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/app/model.hpp"
#include "vrflow/editor/analysis.hpp"
#include "vrflow/editor/edit.hpp"

class QUndoStack;
class QFileDialog;
class QListWidget;
class QPlainTextEdit;
class QMenu;
class QDockWidget;
class QAction;
class QLabel;

namespace vrflow::editor::gui {

class LogView;

/// Where the window's messages go: dialogs by default; tests record them instead.
class Reporter {
 public:
  enum class Choice { Save, Discard, Cancel };
  virtual ~Reporter() = default;
  virtual void error(QWidget* parent, const QString& title, const QString& text);
  virtual void warning(QWidget* parent, const QString& title, const QString& text);
  /// Unsaved changes are about to be lost: save them, discard them, or cancel.
  virtual Choice askToSave(QWidget* parent, const QString& text);
  /// A file name to open or save to; empty to cancel.
  virtual QString fileName(QWidget* parent, bool forSaving, const QString& suggestion);
  /// A host id and address for a new host; false to cancel.
  virtual bool newHost(QWidget* parent, QString& id, QString& address);
  /// A hostfile to import (makeHostfileDialog()), starting in `folder`; empty to cancel.
  virtual QString hostfileName(QWidget* parent, const QString& folder);
};

/// The dialog that picks a hostfile to import: every file shown by default (hostfiles are
/// often named `hosts`, `hostfile` or `nodes`, without a suffix), and a "Hostfiles" filter.
std::unique_ptr<QFileDialog> makeHostfileDialog(QWidget* parent, const QString& folder);

struct EditorOptions {
  std::vector<std::string> packageDirs;  ///< extra package folders, before the search path
  QString settingsFile;                  ///< recent files; empty: the user's settings
  Reporter* reporter = nullptr;          ///< not owned; null: dialogs
  QString vrflowProgram;                 ///< empty: `vrflow` beside this program
  bool rememberRecent = true;            ///< false: opening and saving leave the settings alone
};

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(EditorOptions options, QWidget* parent = nullptr);
  ~MainWindow() override;

  // File.
  void newFile();
  /// Opens a file; a file that cannot be read or is not well-formed keeps the current one and
  /// is reported (false).
  bool openFile(const QString& path);
  bool save();
  bool saveAs(const QString& path);
  /// Asks about unsaved changes; false when the user cancels.
  bool maybeSave();
  QStringList recentFiles() const;

  // Edits (each one undoable).
  bool addNode(const QString& spec, QPointF scenePos);
  bool connectPorts(const app::Endpoint& from, const app::Endpoint& to);
  void deleteSelection();
  void duplicateSelection();
  void copySelection();
  void paste();
  void autoLayout();
  void assignSelectionToHost(const std::string& host);

  // Run (main_window_run.cpp).
  /// Runs the application on this machine (`vrflow run`, N iterations; 0: until it ends).
  void runApplication(int iterations = 0);
  /// Starts `request` (its application is the saved file); false when it cannot start (errors
  /// in the application, not saved, a run going on).
  bool startRun(RunRequest request);
  /// Opens the Run/Launch dialog (window-modal, not blocking); accepting it starts the run.
  void showRunDialog(bool launch);
  /// Opens the list of this user's running runs; accepting follows the chosen one.
  void showAttachDialog();
  /// Follows the registered run `id` (any unique start of it) on the canvas.
  bool attachRun(const QString& id);
  /// Shows the log of `module` of the current or last run in the "Module log" dock.
  void showModuleLog(const std::string& module);
  void stopRun();
  bool running() const;
  /// The choices last made for the current file in the Run/Launch dialog.
  RunRequest rememberedRunRequest(bool launch) const;
  RunController* runController() const { return runs_; }
  /// The status bar's run line: LiveRun::summary() of the current or last run.
  QLabel* runStatus() const { return runStatus_; }
  LogView* moduleLog() const { return moduleLog_; }

  /// Renders the window to a PNG file.
  bool screenshot(const QString& path);

  const app::Application& application() const { return app_; }
  const app::Catalog& catalog() const { return *catalog_; }
  const std::vector<Problem>& problems() const { return problems_; }
  const QString& filePath() const { return path_; }
  bool modified() const;
  Canvas* canvas() const { return canvas_; }
  Palette* palette() const { return palette_; }
  PropertiesPanel* properties() const { return properties_; }
  HostsPanel* hosts() const { return hosts_; }
  QListWidget* problemList() const { return problemList_; }
  QPlainTextEdit* log() const { return log_; }
  QUndoStack* undoStack() const { return undo_; }
  const std::optional<RunReport>& lastRun() const { return lastRun_; }
  /// Iterations/s per module from the running `vrflow`'s event stream (empty when none).
  const std::map<std::string, double>& liveRates() const { return liveRates_; }

  // ---- Live view (main_window_live.cpp) ----
  /// What the editor knows of the run going on or last ended, from its event stream (the run
  /// controller's model).
  LiveRunModel* liveModel() const { return liveModel_; }
  LiveOverlay* liveOverlay() const { return liveOverlay_; }
  RunTable* runTable() const { return runTable_; }
  TimelineView* timeline() const { return timeline_; }
  /// Opens a trace in the timeline dock and shows it; reports why it cannot (false).
  bool openTrace(const QString& path);
  // ---- end of the live view block ----

  /// Applies an edit through the undo stack; reports why when it cannot be made.
  bool apply(Result<Edit> edit, bool quietWhenUnchanged = true);
  /// Called by undo commands after the application changed.
  void applicationChanged();
  app::Application& mutableApplication() { return app_; }

 Q_SIGNALS:
  void runFinished(int exitCode);
  /// The run's statistics were read: liveRates() changed.
  void liveRatesUpdated();

 protected:
  void closeEvent(QCloseEvent* event) override;
  void showEvent(QShowEvent* event) override;

 private:
  void buildMenus();
  void addPackageFolders(const app::Application& app);
  void refresh();
  void updateTitle();
  void addRecent(const QString& path);
  void rebuildRecentMenu();
  void showSelection();
  void problemActivated(int row);
  /// The Run menu and the run controller's signals (main_window_run.cpp).
  /// The Run menu and the run controller's connections (main_window_run.cpp).
  QMenu* setUpRuns();
  void setRunActions(bool runGoesOn);
  /// The (misspelt, suggested) parameter names of a "did you mean" problem, or nullopt.
  static std::optional<std::pair<std::string, std::string>> parameterSuggestion(
      const Problem& problem);
  void finishRun(int exitCode);
  void showLiveRates();
  void setDocument(app::Application app, OpenedText opened, const QString& path);
  void computeFallbackLayout();
  Reporter& reporter() { return *reporter_; }

  EditorOptions options_;
  std::unique_ptr<Reporter> ownReporter_;
  Reporter* reporter_;
  std::unique_ptr<app::Catalog> catalog_;
  QString catalogProblems_;
  app::Application app_;
  OpenedText opened_;
  QString path_;
  std::vector<Problem> problems_;
  std::unique_ptr<QSettings> settings_;

  QUndoStack* undo_;
  Canvas* canvas_;
  Palette* palette_;
  PropertiesPanel* properties_;
  HostsPanel* hosts_;
  QListWidget* problemList_;
  QPlainTextEdit* log_;
  QMenu* recentMenu_ = nullptr;
  QDockWidget* paletteDock_ = nullptr;
  QDockWidget* propertiesDock_ = nullptr;
  QDockWidget* hostsDock_ = nullptr;
  bool shown_ = false;
  QAction* runAction_ = nullptr;
  QAction* stopAction_ = nullptr;

  QAction* runDialogAction_ = nullptr;
  QAction* launchAction_ = nullptr;
  QAction* attachAction_ = nullptr;
  QAction* logAction_ = nullptr;

  RunController* runs_;  ///< the run started or attached from the Run menu
  QLabel* runStatus_;    ///< the run's summary, kept after its end
  LogView* moduleLog_;
  QDockWidget* moduleLogDock_ = nullptr;
  std::optional<RunReport> lastRun_;
  QString runError_;
  std::map<std::string, double> liveRates_;

  // ---- Live view (main_window_live.cpp) ----
  void setUpLiveView(QMenu* runMenu);
  LiveRunModel* liveModel_ = nullptr;
  LiveOverlay* liveOverlay_ = nullptr;
  RunTable* runTable_ = nullptr;
  TimelineView* timeline_ = nullptr;
  QDockWidget* runTableDock_ = nullptr;
  QDockWidget* timelineDock_ = nullptr;
  // ---- end of the live view block ----
};

}  // namespace vrflow::editor::gui
