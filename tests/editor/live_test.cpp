// The live view of a run: the LiveRunModel fed by real event streams (`vrflow run` and a 3-host
// `vrflow launch`) and by synthetic lines for the edge cases, and what the canvas, the hosts
// panel and the run table then show.
#include <QDir>
#include <QFile>
#include <QHeaderView>
#include <QImage>
#include <QPlainTextEdit>
#include <QSignalSpy>
#include <QTableWidget>
#include <QTest>
#include <set>

#include "live_fixture.hpp"

namespace vrflow::editor::gui::testing {
namespace {

class LiveView : public LiveWindow {
 protected:
  LiveRunModel& model() { return *window_->liveModel(); }
  LiveOverlay& overlay() { return *window_->liveOverlay(); }
  Canvas* canvas() { return window_->canvas(); }

  void feed(const QByteArray& line) {
    model().handleLine(line);
    QApplication::processEvents();
  }

  // The index of the canvas connection from `from` to `to` ("node.port").
  std::size_t connectionIndex(const std::string& from, const std::string& to) {
    const auto& connections = window_->application().connections;
    for (std::size_t i = 0; i < connections.size(); ++i) {
      if (app::toString(connections[i].from) == from && app::toString(connections[i].to) == to)
        return i;
    }
    ADD_FAILURE() << "no connection " << from << " -> " << to;
    return 0;
  }

  QString loadOf(int row) {
    QTableWidgetItem* item = window_->hosts()->table()->item(row, 3);
    return item != nullptr ? item->text() : QString();
  }
};

TEST_F(LiveView, ARealRunShowsRatesStateLoadAndQueuesOnTheCanvasUntilItEnds) {
  ASSERT_TRUE(window_->openFile(sourceDir() + "/examples/pipeline/pipeline.xml"));
  // The relay waits 10 ms per message: 150 iterations last well over a second, so the stream
  // carries at least two `stats` and rates can be computed.
  const QString events = dir_.filePath("events.jsonl");
  ASSERT_EQ(vrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n", "150", "--set",
                    "relay.delay-ms=10", "--events", events, "--no-progress"}),
            0);
  const QList<QByteArray> lines = linesOf(events);
  ASSERT_GE(lines.size(), 4);
  // Up to the second `stats`: the run goes on.
  int stats = 0, next = 0;
  while (next < lines.size() && stats < 2) {
    if (lines[next].contains("\"event\":\"stats\"")) ++stats;
    feed(lines[next++]);
  }
  ASSERT_EQ(stats, 2);
  ASSERT_EQ(model().run().phase, LiveRun::Phase::Running);

  ModuleBadgeItem* relay = overlay().badge("relay");
  ASSERT_NE(relay, nullptr);
  EXPECT_EQ(relay->parentItem(), canvas()->nodeItem("relay"));
  EXPECT_TRUE(relay->isVisible());
  EXPECT_GT(relay->figures().rate, 0.0);
  EXPECT_FALSE(relay->failed());
  EXPECT_TRUE(relay->lines().at(0).endsWith(" it/s")) << relay->lines().join("|").toStdString();
  EXPECT_TRUE(relay->lines().at(1).startsWith("wait ")) << relay->lines().join("|").toStdString();
  EXPECT_TRUE(relay->lines().at(2).contains("MiB")) << relay->lines().join("|").toStdString();
  EXPECT_GE(relay->figures().history.size(), 1u);
  EXPECT_TRUE(relay->toolTip().contains("iterations"));
  // Every module has its badge; the relay mostly sleeps in compute (its delay).
  for (const char* id : {"chain", "springs", "gravity", "recorder"})
    EXPECT_NE(overlay().badge(id), nullptr) << id;

  const std::size_t toRecorder = connectionIndex("relay.out", "recorder.in");
  ConnectionLoadItem* load = overlay().connectionLoad(toRecorder);
  ASSERT_NE(load, nullptr);
  EXPECT_EQ(load->parentItem(), canvas()->connectionItem(toRecorder));
  EXPECT_TRUE(load->label().contains("msg/s")) << load->label().toStdString();
  // The label shows while the pointer is over the curve, not piled on the canvas.
  EXPECT_FALSE(load->labelShown());
  {
    QGraphicsView* view = canvas();
    view->centerOn(canvas()->connectionItem(toRecorder)->midPoint());
    QApplication::processEvents();
    const QPoint over = view->mapFromScene(canvas()->connectionItem(toRecorder)->midPoint());
    QMouseEvent move(QEvent::MouseMove, QPointF(over), view->viewport()->mapToGlobal(QPointF(over)),
                     Qt::NoButton, Qt::NoButton, Qt::NoModifier);
    QApplication::sendEvent(view->viewport(), &move);
    QApplication::processEvents();
    EXPECT_TRUE(load->labelShown());
  }
  EXPECT_TRUE(load->label().contains("MiB/s")) << load->label().toStdString();
  EXPECT_TRUE(load->toolTip().contains("queue")) << load->toolTip().toStdString();
  const ConnectionLive* live = model().run().connection("relay.out", "recorder.in");
  ASSERT_NE(live, nullptr);
  ASSERT_GT(live->capacity, 0u);
  EXPECT_EQ(load->color(), colorOfFill(live->fill));

  // The hosts panel's load column and the run table follow the stream.
  EXPECT_TRUE(loadOf(0).contains("cores")) << loadOf(0).toStdString();
  EXPECT_EQ(window_->runTable()->modules()->rowCount(), 5);
  EXPECT_GE(window_->runTable()->connections()->rowCount(), 6);

  // A rebuild of the canvas (as an edit makes) deletes the items with the scene's; the overlay
  // makes them again on the new items.
  canvas()->rebuild();
  QApplication::processEvents();
  QApplication::processEvents();
  ASSERT_NE(overlay().badge("relay"), nullptr);
  EXPECT_EQ(overlay().badge("relay")->parentItem(), canvas()->nodeItem("relay"));
  ASSERT_NE(overlay().connectionLoad(toRecorder), nullptr);

  // The rest of the stream: at the end, the badges and labels give way to the report's totals.
  while (next < lines.size()) feed(lines[next++]);
  EXPECT_EQ(model().run().phase, LiveRun::Phase::Ended);
  EXPECT_EQ(model().run().status, "ok");
  EXPECT_EQ(model().badLines(), 0);
  EXPECT_FALSE(overlay().badge("relay")->isVisible());
  EXPECT_FALSE(overlay().connectionLoad(toRecorder)->isVisible());
  EXPECT_EQ(QString::fromStdString(model().run().summary()).left(9), "Finished:");
}

TEST_F(LiveView, FailedModuleLostHostUnboundedQueueAndBadLinesAreShownWithTheirCause) {
  ASSERT_TRUE(window_->openFile(sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml"));
  feed("not json at all");
  feed("[1, 2, 3]");
  feed(R"({"no_event": true})");
  EXPECT_EQ(model().badLines(), 3);
  EXPECT_EQ(model().run().phase, LiveRun::Phase::None);
  feed(
      R"({"event":"started","time":0.1,"application":"pipeline","file":"p.xml",)"
      R"("hosts":[{"id":"a","address":"127.0.0.1"},{"id":"b","address":"127.0.0.2"},)"
      R"({"id":"c","address":"127.0.0.3"}],"modules":[{"id":"chain","type":"core/points","host":"a"},)"
      R"({"id":"springs","type":"core/spring","host":"b"},{"id":"gravity","type":"core/gravity","host":"c"},)"
      R"({"id":"relay","type":"core/relay","host":"b"},{"id":"recorder","type":"core/recorder","host":"c"}]})");
  const auto stats = [&](double time, int iterations, int length, int sent) {
    const std::string i = std::to_string(iterations), t = std::to_string(time);
    feed(QByteArray::fromStdString(
        R"({"event":"stats","time":)" + t +
        R"(,"host":"a","modules":[{"id":"chain","iterations":)" + i +
        R"(,"state":"computing","compute_ns":)" + std::to_string(iterations * 1000000) +
        R"(,"wait_ns":)" + std::to_string(iterations * 3000000) + R"(,"cpu_ns":)" +
        std::to_string(iterations * 2000000) + R"(,"rss_bytes":10485760}],"connections":[)" +
        R"({"from":"chain.objects","to":"springs.objects","length":)" + std::to_string(length) +
        R"(,"capacity":16,"messages":)" + i + R"(,"bytes":)" + std::to_string(iterations * 1024) +
        R"(,"dropped":0},{"from":"chain.objects","to":"relay.in","length":40,"capacity":0,"messages":)" +
        i + R"(,"bytes":0,"dropped":0}],"filters":[],"links":[{"peer":1,"messages_sent":)" +
        std::to_string(sent) + R"(,"bytes_sent":)" + std::to_string(sent * 1048576) +
        R"(,"messages_received":0,"bytes_received":0}],"t_ns":1})"));
  };
  stats(1.0, 100, 8, 0);
  stats(2.0, 300, 16, 100);
  const LiveRun& run = model().run();
  ASSERT_EQ(run.phase, LiveRun::Phase::Running);
  EXPECT_DOUBLE_EQ(run.modules.at("chain").rate, 200.0);
  EXPECT_DOUBLE_EQ(run.modules.at("chain").waitShare, 0.75);
  EXPECT_DOUBLE_EQ(run.modules.at("chain").cpu, 0.4);
  EXPECT_DOUBLE_EQ(run.host("a")->cpu, 0.4);
  EXPECT_DOUBLE_EQ(run.host("a")->rssMiB, 10.0);

  // A full queue is red, an unbounded one grey.
  ConnectionLoadItem* full =
      overlay().connectionLoad(connectionIndex("chain.objects", "springs.objects"));
  ASSERT_NE(full, nullptr);
  EXPECT_EQ(full->color(), QColor(220, 40, 30));
  EXPECT_TRUE(full->toolTip().contains("queue 16 of 16 (100% full)"))
      << full->toolTip().toStdString();
  EXPECT_TRUE(full->label().startsWith("200 msg/s")) << full->label().toStdString();
  ConnectionLoadItem* unbounded =
      overlay().connectionLoad(connectionIndex("chain.objects", "relay.in"));
  ASSERT_NE(unbounded, nullptr);
  EXPECT_EQ(unbounded->color(), colorOfFill(-1));
  EXPECT_TRUE(unbounded->toolTip().contains("queue 40 (unbounded)"));
  EXPECT_EQ(colorOfFill(0.5), QColor(240, 170, 0));  // half full: amber

  // The link from a to b: 100 messages (100 MiB) in one second.
  ASSERT_EQ(overlay().links().size(), 1u);
  LinkItem* link = overlay().links().front();
  EXPECT_EQ(link->hostA(), "a");
  EXPECT_EQ(link->hostB(), "b");
  ASSERT_EQ(link->lines().size(), 1);
  EXPECT_EQ(link->lines().at(0), "a \u2192 b: 100 msg/s \u00b7 100.0 MiB/s");
  EXPECT_FALSE(link->lost());

  // The springs die of the memory limit; then host b loses host c.
  feed(R"({"event":"module_exit","time":2.5,"module":"springs","host":"b","exit":"signal 9",)"
       R"js("cause":"killed at its memory limit (64 MiB)"})js");
  ModuleBadgeItem* springs = overlay().badge("springs");
  ASSERT_NE(springs, nullptr);
  EXPECT_TRUE(springs->failed());
  EXPECT_EQ(springs->lines().back(), "failed: killed at its memory limit (64 MiB)");
  EXPECT_TRUE(springs->toolTip().contains("memory limit"));
  feed(
      R"({"event":"end","time":3.0,"exit_code":1,"status":"failed",)"
      R"js("error":"host 'b': lost the link to host 'c' (127.0.0.3:4100): no heartbeat for 3 s"})js");
  EXPECT_EQ(run.phase, LiveRun::Phase::Ended);
  ASSERT_NE(run.host("c"), nullptr);
  EXPECT_TRUE(run.host("c")->lost);
  for (const char* onC : {"gravity", "recorder"}) {
    ModuleBadgeItem* badge = overlay().badge(onC);
    ASSERT_NE(badge, nullptr) << onC;
    EXPECT_TRUE(badge->failed()) << onC;
    EXPECT_TRUE(badge->isVisible()) << onC;  // failures stay after the end
    EXPECT_TRUE(badge->lines().back().startsWith("failed: host 'c' lost: ")) << onC;
  }
  EXPECT_FALSE(overlay().badge("chain")->isVisible());
  EXPECT_TRUE(springs->isVisible());
  // The hosts panel: c lost, in red, with its cause.
  EXPECT_EQ(loadOf(2), "lost");
  QTableWidgetItem* c = window_->hosts()->table()->item(2, 3);
  EXPECT_EQ(c->foreground().color(), QColor(200, 20, 20));
  EXPECT_TRUE(c->toolTip().contains("no heartbeat")) << c->toolTip().toStdString();
  EXPECT_TRUE(loadOf(0).contains("cores"));
  EXPECT_EQ(QString::fromStdString(run.summary()),
            "Failed: host 'b': lost the link to host 'c' (127.0.0.3:4100): no heartbeat for 3 s "
            "[exit 1]");
  EXPECT_FALSE(run.host("b")->lost);  // b said so; c is the lost one

  // A new `started` begins the next run: the failures are forgotten.
  feed(
      R"({"event":"started","time":0.0,"application":"pipeline","file":"p.xml","hosts":[],"modules":[]})");
  EXPECT_EQ(model().run().phase, LiveRun::Phase::Running);
  EXPECT_TRUE(model().run().modules.empty());
  EXPECT_EQ(overlay().badge("springs"), nullptr);
}

TEST_F(LiveView, RunFromTheMenuFillsTheRunTableWithTheReportsTotalsSortedByAClick) {
  // A copy of the example: the run's output folder is the file's folder (nothing may be written
  // into the source tree).
  const QString file = dir_.filePath("pipeline.xml");
  ASSERT_TRUE(QFile::copy(sourceDir() + "/examples/pipeline/pipeline.xml", file));
  ASSERT_TRUE(window_->openFile(file));
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  window_->runApplication(40);
  ASSERT_TRUE(finished.wait(60000)) << window_->log()->toPlainText().toStdString();
  ASSERT_EQ(finished.at(0).at(0).toInt(), 0) << window_->log()->toPlainText().toStdString();
  // The stream reached the model through the run console.
  EXPECT_EQ(model().run().phase, LiveRun::Phase::Ended);
  EXPECT_EQ(model().run().modules.size(), 5u);
  QTableWidget* modules = window_->runTable()->modules();
  ASSERT_EQ(modules->rowCount(), 5);
  // Sort by module name with a click on its header, then read the totals.
  QHeaderView* header = modules->horizontalHeader();
  const QPoint name(header->sectionViewportPosition(0) + 5, header->height() / 2);
  QTest::mouseClick(header->viewport(), Qt::LeftButton, {}, name);
  if (modules->item(0, 0)->text() != "chain")
    QTest::mouseClick(header->viewport(), Qt::LeftButton, {}, name);
  QStringList order;
  for (int row = 0; row < modules->rowCount(); ++row) order << modules->item(row, 0)->text();
  EXPECT_EQ(order, QStringList({"chain", "gravity", "recorder", "relay", "springs"}));
  for (int row = 0; row < modules->rowCount(); ++row) {
    EXPECT_EQ(modules->item(row, 3)->text(), "40") << order[row].toStdString();
    EXPECT_EQ(modules->item(row, 1)->text(), "local");
  }
  QTableWidget* connections = window_->runTable()->connections();
  ASSERT_EQ(connections->rowCount(), 6);
  bool relayed = false;
  for (int row = 0; row < connections->rowCount(); ++row) {
    if (connections->item(row, 0)->text() == "relay.out") {
      relayed = true;
      EXPECT_EQ(connections->item(row, 6)->text(), "40");
    }
  }
  EXPECT_TRUE(relayed);
}

TEST_F(LiveView, AThreeHostLaunchIsFollowedLiveWithItsLinksAndHostsLoad) {
  ASSERT_TRUE(window_->openFile(sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml"));
  const QString events = dir_.filePath("launch.jsonl");
  ASSERT_EQ(vrflow({"launch", sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml", "-n",
                    "150", "--set", "relay.delay-ms=10", "--events", events}),
            0);
  const QList<QByteArray> lines = linesOf(events);
  ASSERT_GE(lines.size(), 4);
  // Up to the first `stats` in which modules have ended: the run in full flow.
  int next = 0;
  while (next + 1 < lines.size() && !(lines[next].contains("\"event\":\"stats\"") &&
                                      lines[next].contains("\"state\":\"ended\"")))
    feed(lines[next++]);
  const LiveRun& run = model().run();
  ASSERT_EQ(run.phase, LiveRun::Phase::Running);
  ASSERT_EQ(run.hosts.size(), 3u);
  EXPECT_EQ(run.modules.at("springs").host, "b");
  EXPECT_FALSE(run.links.empty());
  // chain (a) sends to springs (b), gravity (c) and relay (b): bands between a and b, a and c.
  std::set<std::pair<QString, QString>> pairs;
  for (LinkItem* link : overlay().links()) {
    pairs.insert({link->hostA(), link->hostB()});
    EXPECT_FALSE(link->lines().isEmpty());
    EXPECT_TRUE(link->toolTip().startsWith("between hosts ")) << link->toolTip().toStdString();
  }
  EXPECT_EQ(pairs.count({"a", "b"}), 1u);
  EXPECT_EQ(pairs.count({"a", "c"}), 1u);
  for (int row = 0; row < 3; ++row) EXPECT_TRUE(loadOf(row).contains("MiB")) << row;
  for (const char* id : {"chain", "springs", "gravity", "relay", "recorder"}) {
    ASSERT_NE(overlay().badge(id), nullptr) << id;
    EXPECT_TRUE(overlay().badge(id)->isVisible()) << id;
  }
  // The window as it stands, for the docs and for a person to look at.
  canvas()->fitAll();
  QApplication::processEvents();
  const QImage shot = window_->grab().toImage();
  ASSERT_FALSE(shot.isNull());
  const QString shots = QCoreApplication::applicationDirPath() + "/../test-screenshots";
  QDir().mkpath(shots);
  EXPECT_TRUE(shot.save(shots + "/live_pipeline_3hosts.png"));
  while (next < lines.size()) feed(lines[next++]);
  EXPECT_EQ(run.status, "ok");
  EXPECT_TRUE(overlay().links().front()->lines().front().contains("messages"));
  // After the run the links' totals show under the pointer only, never piled on the nodes.
  for (const LinkItem* link : overlay().links()) EXPECT_FALSE(link->labelShown());
}

}  // namespace
}  // namespace vrflow::editor::gui::testing
