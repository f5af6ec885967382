// The window's live view of a run (issue 20 items 2 and 3): the LiveRunModel fed by the run's
// event stream, the overlay on the canvas, the hosts' load, the run table and the timeline docks.
#include <QDockWidget>
#include <QFileInfo>
#include <QMenu>

#include "main_window.hpp"

namespace vrflow::editor::gui {

void MainWindow::setUpLiveView(QMenu* runMenu) {
  liveModel_ = runs_->live();  // the run controller's model: started and attached runs alike
  liveOverlay_ = new LiveOverlay(canvas_, liveModel_, this);
  runTable_ = new RunTable;
  timeline_ = new TimelineView;
  connect(liveModel_, &LiveRunModel::changed, this, [this] {
    hosts_->showLoad(liveModel_->run());
    runTable_->showLive(liveModel_->run());
  });
  connect(this, &MainWindow::runFinished, this, [this] {
    if (lastRun_) runTable_->showReport(*lastRun_, liveModel_->run());
    // A run that wrote a trace opens it in the timeline (its dock stays where it is).
    const QString trace = runs_->traceFile();
    if (!trace.isEmpty() && QFileInfo::exists(trace)) timeline_->open(trace);
  });

  runTableDock_ = new QDockWidget("Run table", this);
  runTableDock_->setObjectName("Run table");
  runTableDock_->setWidget(runTable_);
  addDockWidget(Qt::BottomDockWidgetArea, runTableDock_);
  timelineDock_ = new QDockWidget("Timeline", this);
  timelineDock_->setObjectName("Timeline");
  timelineDock_->setWidget(timeline_);
  addDockWidget(Qt::BottomDockWidgetArea, timelineDock_);
  const auto docks = findChildren<QDockWidget*>();
  for (QDockWidget* dock : docks) {
    if (dock->objectName() == "Run log") {
      tabifyDockWidget(dock, runTableDock_);
      tabifyDockWidget(dock, timelineDock_);
    }
  }
  for (QDockWidget* dock : docks) {
    if (dock->objectName() == "Problems") dock->raise();  // the first tab stays in front
  }
  runMenu->addSeparator();
  runMenu->addAction("Open &trace\u2026", this, [this] {
    const QString path = reporter().fileName(this, false, QString());
    if (!path.isEmpty()) openTrace(path);
  });
}

bool MainWindow::openTrace(const QString& path) {
  if (!timeline_->open(path)) {
    reporter().error(this, "Cannot open the trace", timeline_->error());
    return false;
  }
  timelineDock_->show();
  timelineDock_->raise();
  timeline_->fitAll();
  return true;
}

}  // namespace vrflow::editor::gui
