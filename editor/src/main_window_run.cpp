// The run parts of the main window: the Run menu, starting, attaching, stopping, the status
// bar's run line and the module log. The process and its event stream are RunController's.
#include <QAction>
#include <QDockWidget>
#include <QFileInfo>
#include <QLabel>
#include <QMenu>
#include <QMenuBar>
#include <QPlainTextEdit>
#include <QStatusBar>

#include "attach_dialog.hpp"
#include "log_view.hpp"
#include "main_window.hpp"
#include "qt_text.hpp"
#include "run_dialog.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::editor::gui {

QMenu* MainWindow::setUpRuns() {
  connect(runs_, &RunController::logLine, log_, &QPlainTextEdit::appendPlainText);
  connect(runs_, &RunController::finished, this, &MainWindow::finishRun);
  connect(runs_->live(), &LiveRunModel::changed, this, &MainWindow::showLiveRates);
  runStatus_->setObjectName("runStatus");
  statusBar()->addPermanentWidget(runStatus_);

  QMenu* runMenu = menuBar()->addMenu("&Run");
  runAction_ = runMenu->addAction("&Run on this machine", QKeySequence(Qt::Key_F5), this,
                                  [this] { runApplication(); });
  runDialogAction_ = runMenu->addAction("Run\u2026", QKeySequence(Qt::CTRL | Qt::Key_R), this,
                                        [this] { showRunDialog(false); });
  launchAction_ =
      runMenu->addAction("&Launch on hosts\u2026", this, [this] { showRunDialog(true); });
  attachAction_ = runMenu->addAction("&Attach to a run\u2026", this, &MainWindow::showAttachDialog);
  stopAction_ =
      runMenu->addAction("&Stop", QKeySequence(Qt::SHIFT | Qt::Key_F5), this, &MainWindow::stopRun);
  stopAction_->setEnabled(false);
  runMenu->addSeparator();
  logAction_ = runMenu->addAction("Show &log of the selected module", this, [this] {
    const auto selected = canvas_->selectedNodes();
    if (selected.size() == 1) {
      showModuleLog(selected.front());
    } else {
      statusBar()->showMessage("Select one module first", 4000);
    }
  });
  connect(properties_, &PropertiesPanel::overrideForRunRequested, this,
          [this](const std::string& node, const std::string& name, const std::string& value) {
            RunRequest request = rememberedRunRequest(false);
            request.overrides.emplace_back(qtText(node + "." + name), qtText(value));
            saveRunChoices(*settings_, request);
            statusBar()->showMessage(qtText("The next run sets " + node + "." + name + "=" + value),
                                     8000);
          });
  return runMenu;
}

bool MainWindow::running() const {
  return runs_->running();
}

RunRequest MainWindow::rememberedRunRequest(bool launch) const {
  RunRequest request = loadRunChoices(*settings_, path_);
  request.application = path_;
  request.launch = launch;
  request.packageDirs.clear();
  for (const auto& dir : options_.packageDirs) request.packageDirs << qtText(dir);
  return request;
}

void MainWindow::runApplication(int iterations) {
  RunRequest request;
  request.iterations = iterations;
  for (const auto& dir : options_.packageDirs) request.packageDirs << qtText(dir);
  startRun(std::move(request));
}

bool MainWindow::startRun(RunRequest request) {
  if (running()) return false;
  if (app::hasErrors([this] {
        std::vector<app::Diagnostic> d;
        for (const auto& p : problems_) d.push_back({{}, p.severity, p.message});
        return d;
      }())) {
    reporter().error(this, "Cannot run", "The application has errors; see the Problems list.");
    return false;
  }
  if ((path_.isEmpty() || modified()) && !save()) return false;
  request.application = path_;
  lastRun_.reset();
  liveRates_.clear();
  canvas_->state().live.clear();
  runError_.clear();
  refresh();
  // A process that cannot start ends through finished(-1) (finishRun); the log says why.
  if (!runs_->start(request)) return false;
  setRunActions(true);
  runStatus_->setText(qtText(runs_->live()->run().summary()));
  return true;
}

bool MainWindow::attachRun(const QString& id) {
  if (running()) return false;
  lastRun_.reset();
  liveRates_.clear();
  canvas_->state().live.clear();
  if (!runs_->attach(id)) return false;
  setRunActions(true);
  runStatus_->setText(qtText(runs_->live()->run().summary()));
  return true;
}

void MainWindow::showRunDialog(bool launch) {
  auto* dialog = new RunDialog(runs_->program(), app_, rememberedRunRequest(launch), this);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  connect(dialog, &QDialog::accepted, this, [this, dialog] {
    const RunRequest request = dialog->request();
    saveRunChoices(*settings_, request);
    startRun(request);
  });
  dialog->open();
}

void MainWindow::showAttachDialog() {
  auto* dialog = new AttachDialog(runs_->listRuns(false), this);
  dialog->setAttribute(Qt::WA_DeleteOnClose);
  connect(dialog, &QDialog::accepted, this, [this, dialog] { attachRun(dialog->chosenRun()); });
  dialog->open();
}

void MainWindow::showModuleLog(const std::string& module) {
  if (runs_->runId().isEmpty()) {
    statusBar()->showMessage("No run yet: a module's log exists once it ran", 6000);
    return;
  }
  moduleLog_->follow(runs_->program(), runs_->runId(), qtText(module));
  moduleLogDock_->setWindowTitle(qtText("Log of " + module));
  moduleLogDock_->show();
  moduleLogDock_->raise();
}

void MainWindow::stopRun() {
  if (running()) runs_->stop();
}

void MainWindow::showLiveRates() {
  const LiveRun& run = runs_->live()->run();
  runStatus_->setText(qtText(run.summary()));
  std::map<std::string, double> rates;
  for (const auto& [id, module] : run.modules) {
    if (!module.history.empty()) rates[id] = module.rate;
  }
  if (rates.empty() || run.phase != LiveRun::Phase::Running) return;
  liveRates_ = std::move(rates);
  canvas_->setLiveRates(liveRates_);
  Q_EMIT liveRatesUpdated();
}

void MainWindow::setRunActions(bool runGoesOn) {
  for (QAction* action : {runAction_, runDialogAction_, launchAction_, attachAction_})
    action->setEnabled(!runGoesOn);
  stopAction_->setEnabled(runGoesOn);
}

void MainWindow::finishRun(int exitCode) {
  setRunActions(false);
  lastRun_ = runs_->report();
  canvas_->state().live.clear();  // the report's figures replace the live ones
  QString summary;
  if (exitCode == 0) {
    summary = "Run finished";
  } else if (exitCode == run::kExitInterrupted) {
    summary = "Run stopped";
  } else {
    summary = QString("Run failed (exit %1)").arg(exitCode);
    if (lastRun_ && !lastRun_->error.empty()) summary += ": " + qtText(lastRun_->error);
  }
  if (lastRun_ && lastRun_->wallSeconds > 0)
    summary += QString(" after %1 s").arg(lastRun_->wallSeconds, 0, 'f', 2);
  log_->appendPlainText(summary);
  runError_ = exitCode == 0 ? QString() : summary;
  refresh();
  if (lastRun_ && !lastRun_->failedModule.empty()) canvas_->selectOnly({lastRun_->failedModule});
  // The reason stays: the event stream's end, or what the editor knows when there was none.
  const LiveRun& live = runs_->live()->run();
  runStatus_->setText(live.phase == LiveRun::Phase::Ended ? qtText(live.summary()) : summary);
  Q_EMIT runFinished(exitCode);
}

}  // namespace vrflow::editor::gui
