// The timeline dock: the trace of a real run of examples/pipeline (`vrflow run --trace`) drawn
// per module, with its message arrows, zoomed by real wheel events and opened from the Run menu.
#include <QDir>
#include <QDockWidget>
#include <QGraphicsItem>
#include <QMenuBar>
#include <QTest>
#include <QWheelEvent>
#include <cmath>

#include "live_fixture.hpp"

namespace vrflow::editor::gui::testing {
namespace {

class Timeline : public LiveWindow {
 protected:
  // Runs examples/pipeline for `iterations` with a trace; its path.
  QString tracedRun(int iterations) {
    const QString trace = dir_.filePath("trace.json");
    EXPECT_EQ(vrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n",
                      QString::number(iterations), "--trace", trace, "--no-progress"}),
              0);
    return trace;
  }

  void wheel(TimelineView* view, QPoint at, int delta) {
    QWheelEvent event(QPointF(at), view->viewport()->mapToGlobal(QPointF(at)), QPoint(),
                      QPoint(0, delta), Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
    QApplication::sendEvent(view->viewport(), &event);
    QApplication::processEvents();
  }

  void mouse(TimelineView* view, QEvent::Type type, QPoint at, Qt::MouseButton button,
             Qt::MouseButtons buttons) {
    sendMouse(view, type, at, button, buttons);
    QApplication::processEvents();
  }

  // The Run menu's action named `text`.
  QAction* runMenuAction(const QString& text) {
    for (QAction* menu : window_->menuBar()->actions()) {
      if (menu->text() != "&Run" || menu->menu() == nullptr) continue;
      for (QAction* action : menu->menu()->actions()) {
        if (action->text() == text) return action;
      }
    }
    return nullptr;
  }
};

TEST_F(Timeline, ShowsEachModulesWaitAndComputeSpansAndTheMessagesBetweenThem) {
  const QString trace = tracedRun(30);
  TimelineView* view = window_->timeline();
  ASSERT_TRUE(view->open(trace)) << view->error().toStdString();
  ASSERT_EQ(view->rows().size(), 5);
  EXPECT_EQ(view->rows().front(), "host local (127.0.0.1) / chain");
  for (const char* module : {"chain", "springs", "gravity", "relay", "recorder"}) {
    EXPECT_EQ(view->spanCount(module, "compute"), 30) << module;
    EXPECT_GE(view->spanCount(module, "wait"), 29) << module;
  }
  // Each of chain's outputs reaches springs, gravity and relay; their forces come back; the
  // relay forwards to the recorder: at least one arrow per delivered message.
  EXPECT_GE(view->arrowCount(), 30 * 5);
  EXPECT_GT(view->durationMs(), 0.0);

  // A span has its tooltip: what it is, which module, which iteration, when.
  int tipped = 0;
  for (QGraphicsItem* item : view->scene()->items()) {
    if (item->toolTip().startsWith("compute \u00b7 relay \u00b7 iteration ")) ++tipped;
  }
  EXPECT_EQ(tipped, 30);

  // The dock as a person sees it, zoomed on the first iterations.
  view->resize(1000, 200);
  view->fitAll();
  const QPoint left(200, 60);
  for (int i = 0; i < 10; ++i) wheel(view, left, 120);
  const QString shots = QCoreApplication::applicationDirPath() + "/../test-screenshots";
  QDir().mkpath(shots);
  EXPECT_TRUE(view->grab().save(shots + "/timeline_pipeline.png"));
}

TEST_F(Timeline, TheWheelZoomsTheTimeAxisAroundTheCursorAndADragPans) {
  ASSERT_TRUE(window_->openTrace(tracedRun(20))) << reporter_.errors.join("\n").toStdString();
  TimelineView* view = window_->timeline();
  view->resize(900, 240);
  view->fitAll();
  QApplication::processEvents();
  const double fitted = view->pixelsPerMs();
  ASSERT_GT(fitted, 0.0);
  const QPoint at(600, 60);
  wheel(view, at, 120);
  EXPECT_NEAR(view->pixelsPerMs(), fitted * 1.25, fitted * 1e-6);
  EXPECT_DOUBLE_EQ(view->transform().m22(), 1.0);  // rows keep their height
  wheel(view, at, 240);
  // Once the trace is wider than the view, the time under the cursor stays under it.
  const double zoomed = view->pixelsPerMs();
  EXPECT_NEAR(zoomed, fitted * std::pow(1.25, 3), fitted * 1e-6);
  const QPointF before = view->mapToScene(at);
  wheel(view, at, 120);
  wheel(view, at, 120);
  EXPECT_NEAR(view->pixelsPerMs(), zoomed * 1.25 * 1.25, zoomed * 1e-6);
  EXPECT_NEAR(view->mapToScene(at).x(), before.x(), 2 / view->pixelsPerMs());
  wheel(view, at, -240);
  EXPECT_NEAR(view->pixelsPerMs(), zoomed, zoomed * 1e-6);

  // Zoomed in, a drag to the left shows later times.
  for (int i = 0; i < 8; ++i) wheel(view, at, 120);
  const double left = view->mapToScene(QPoint(300, 60)).x();
  mouse(view, QEvent::MouseButtonPress, QPoint(500, 60), Qt::LeftButton, Qt::LeftButton);
  mouse(view, QEvent::MouseMove, QPoint(400, 60), Qt::NoButton, Qt::LeftButton);
  mouse(view, QEvent::MouseMove, QPoint(300, 60), Qt::NoButton, Qt::LeftButton);
  mouse(view, QEvent::MouseButtonRelease, QPoint(300, 60), Qt::LeftButton, Qt::NoButton);
  EXPECT_GT(view->mapToScene(QPoint(300, 60)).x(), left);
}

TEST_F(Timeline, OpensFromTheRunMenuAndRefusesAFileThatIsNoTrace) {
  QAction* open = runMenuAction("Open &trace\u2026");
  ASSERT_NE(open, nullptr);
  reporter_.nextFile = tracedRun(10);
  open->trigger();
  EXPECT_TRUE(reporter_.errors.isEmpty()) << reporter_.errors.join("\n").toStdString();
  EXPECT_EQ(window_->timeline()->file(), reporter_.nextFile);
  EXPECT_EQ(window_->timeline()->rows().size(), 5);
  // Not a trace: one message naming the file; the shown trace stays.
  const QString notTrace = sourceDir() + "/examples/pipeline/pipeline.xml";
  reporter_.nextFile = notTrace;
  open->trigger();
  ASSERT_EQ(reporter_.errors.size(), 1);
  EXPECT_TRUE(reporter_.errors.front().contains(notTrace + ": not a trace"))
      << reporter_.errors.front().toStdString();
  EXPECT_EQ(window_->timeline()->rows().size(), 5);
}

}  // namespace
}  // namespace vrflow::editor::gui::testing
