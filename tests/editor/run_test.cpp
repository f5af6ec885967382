// The editor as the console of runs, driven like a user would (offscreen): the Run/Launch
// dialog, a 1-host run and a 3-host launch followed live through the real `vrflow`'s event
// stream, attach to and stop a run started outside, a module's log, a failing host, and the
// scripted --launch.
#include <gtest/gtest.h>

#include <QAbstractButton>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QMenuBar>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QRadioButton>
#include <QSignalSpy>
#include <QSpinBox>
#include <QStatusBar>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <filesystem>
#include <memory>
#include <set>

#include "attach_dialog.hpp"
#include "log_view.hpp"
#include "main_window.hpp"
#include "offscreen_app.hpp"
#include "run_dialog.hpp"

namespace vrflow::editor::gui {
namespace {

namespace fs = std::filesystem;

QString sourceDir() {
  return QString(VRFLOW_TEST_SOURCE_DIR);
}

QString binDir() {
  return QCoreApplication::applicationDirPath();
}

QString testPackages() {
  return QString::fromStdString(
      (fs::path(binDir().toStdString()) / ".." / "test-packages").string());
}

// A chatter that prints three lines on each stream, then forwards through a slow relay for as
// long as the run goes on.
const char* kEndlessApp = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="endless" version="1">
  <modules>
    <module id="chatter" package="testing" type="chatter"/>
    <module id="relay" package="core" type="relay"><param name="delay-ms" value="20"/></module>
    <module id="recorder" package="core" type="recorder"/>
  </modules>
  <connections>
    <connection from="chatter.out" to="relay.in"/>
    <connection from="relay.out" to="recorder.in"/>
  </connections>
</application>
)";

// Two hosts on this machine; the module on host b exits with status 7 at its third iteration.
const char* kFailingHostApp = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="failing" version="1">
  <hosts>
    <host id="a" address="127.0.0.1"/>
    <host id="b" address="127.0.0.2"/>
  </hosts>
  <modules>
    <module id="source" package="core" type="source" host="a"/>
    <module id="crash" package="testing" type="crash" host="b"/>
    <module id="recorder" package="core" type="recorder" host="a"/>
  </modules>
  <connections>
    <connection from="source.out" to="crash.in"/>
    <connection from="crash.out" to="recorder.in"/>
  </connections>
</application>
)";

class EditorRuns : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_run_tests"); }

  void SetUp() override {
    ASSERT_TRUE(dir_.isValid());
    // This test's own registry of runs: `vrflow list` shows only the runs it started.
    ASSERT_TRUE(QDir(dir_.path()).mkpath("runtime") && QDir(dir_.path()).mkpath("state"));
    QFile::setPermissions(dir_.filePath("runtime"),
                          QFile::ReadOwner | QFile::WriteOwner | QFile::ExeOwner);
    qputenv("XDG_RUNTIME_DIR", dir_.filePath("runtime").toUtf8());
    qputenv("XDG_STATE_HOME", dir_.filePath("state").toUtf8());
    EditorOptions options;
    options.settingsFile = dir_.filePath("settings.ini");
    options.packageDirs.push_back(testPackages().toStdString());
    window_ = std::make_unique<MainWindow>(options);
    window_->resize(1400, 860);
    window_->show();
    QApplication::processEvents();
  }

  void TearDown() override {
    if (outside_.state() != QProcess::NotRunning) {
      outside_.terminate();
      outside_.waitForFinished(30000);
    }
  }

  QString write(const QString& name, const QByteArray& text) {
    QFile file(dir_.filePath(name));
    EXPECT_TRUE(file.open(QIODevice::WriteOnly));
    file.write(text);
    return file.fileName();
  }

  QString copyExample(const QString& relative) {
    QFile in(sourceDir() + "/" + relative);
    EXPECT_TRUE(in.open(QIODevice::ReadOnly));
    return write(QFileInfo(relative).fileName(), in.readAll());
  }

  // The Run menu's action whose text starts with `text`, triggered as a click on it would.
  void runMenu(const QString& text) {
    for (QAction* menu : window_->menuBar()->actions()) {
      if (menu->text() != "&Run") continue;
      for (QAction* action : menu->menu()->actions()) {
        if (action->text().remove('&').startsWith(text)) {
          ASSERT_TRUE(action->isEnabled()) << text.toStdString();
          action->trigger();
          QApplication::processEvents();
          return;
        }
      }
    }
    FAIL() << "no Run menu action " << text.toStdString();
  }

  RunDialog* runDialog() {
    auto* dialog = window_->findChild<RunDialog*>();
    EXPECT_NE(dialog, nullptr);
    if (dialog != nullptr) {
      EXPECT_TRUE(QTest::qWaitForWindowExposed(dialog));
    }
    return dialog;
  }

  static void clickOk(QDialog* dialog) {
    auto* buttons = dialog->findChild<QDialogButtonBox*>();
    ASSERT_NE(buttons, nullptr);
    QTest::mouseClick(buttons->button(QDialogButtonBox::Ok), Qt::LeftButton);
    QApplication::processEvents();
  }

  static void typeInto(QWidget* field, const QString& text) {
    field->setFocus();
    QTest::keyClick(field, Qt::Key_A, Qt::ControlModifier);
    QTest::keyClick(field, Qt::Key_Delete);
    QTest::keyClicks(field, text);
  }

  std::string log() const { return window_->log()->toPlainText().toStdString(); }
  QString status() const { return window_->runStatus()->text(); }

  // The `vrflow list --json` entries.
  static QJsonArray listRuns() {
    QProcess list;
    list.start(binDir() + "/vrflow", {"list", "--json"});
    list.waitForFinished(30000);
    return QJsonDocument::fromJson(list.readAllStandardOutput()).array();
  }

  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> window_;
  QProcess outside_;  ///< a run started outside the editor
};

TEST_F(EditorRuns, TheRunDialogStartsARunFollowedLiveToItsEndAndTheReasonStays) {
  ASSERT_TRUE(window_->openFile(copyExample("examples/pipeline/pipeline.xml")));
  const QString out = dir_.filePath("results");
  // An override asked from the properties panel becomes a row of the dialog.
  Q_EMIT window_->properties()->overrideForRunRequested("relay", "delay-ms", "5");
  QTest::keyClick(window_.get(), Qt::Key_R, Qt::ControlModifier);
  if (window_->findChild<RunDialog*>() == nullptr) runMenu("Run\u2026");  // no focus offscreen
  RunDialog* dialog = runDialog();
  ASSERT_NE(dialog, nullptr);
  EXPECT_TRUE(dialog->hereButton()->isChecked());
  ASSERT_EQ(dialog->overrides()->rowCount(), 1);
  EXPECT_EQ(dialog->overrides()->item(0, 0)->text(), "relay.delay-ms");
  typeInto(dialog->iterations(), "120");
  typeInto(dialog->outputFolder(), out);
  QTest::mouseClick(dialog->trace(), Qt::LeftButton, {}, QPoint(8, dialog->trace()->height() / 2));
  ASSERT_TRUE(dialog->trace()->isChecked());
  const QString command = dialog->commandLineView()->toPlainText();
  EXPECT_TRUE(command.contains(" run ")) << command.toStdString();
  EXPECT_TRUE(command.contains("--iterations 120")) << command.toStdString();
  EXPECT_TRUE(command.contains("--set relay.delay-ms=5")) << command.toStdString();
  EXPECT_TRUE(command.contains("--trace " + out + "/pipeline.trace.json")) << command.toStdString();
  EXPECT_TRUE(command.contains("--events -")) << command.toStdString();
  EXPECT_TRUE(command.startsWith("cd " + out)) << command.toStdString();

  QSignalSpy started(window_->runController(), &RunController::started);
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  std::set<std::string> runningLines;
  QObject::connect(window_->runController()->live(), &LiveRunModel::changed, window_.get(), [&] {
    if (window_->runController()->live()->run().phase == LiveRun::Phase::Running)
      runningLines.insert(status().toStdString());
  });
  clickOk(dialog);
  ASSERT_EQ(started.count(), 1) << log();
  ASSERT_TRUE(finished.wait(120000)) << log();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 0) << log();
  // While it ran, the status bar said so; at the end it says how it ended, and that stays.
  ASSERT_FALSE(runningLines.empty());
  EXPECT_TRUE(runningLines.begin()->rfind("Running: ", 0) == 0) << *runningLines.begin();
  EXPECT_TRUE(status().startsWith("Finished: 120 iterations")) << status().toStdString();
  QTest::qWait(1500);
  EXPECT_TRUE(status().startsWith("Finished: 120 iterations")) << status().toStdString();
  // An edit after the run writes its own message; the run's line stays beside it.
  window_->autoLayout();
  EXPECT_TRUE(window_->statusBar()->currentMessage().startsWith("Valid")) << log();
  EXPECT_TRUE(status().startsWith("Finished: 120 iterations")) << status().toStdString();
  EXPECT_TRUE(window_->runStatus()->isVisible());
  const LiveRun& run = window_->runController()->live()->run();
  EXPECT_EQ(run.modules.size(), 5u);
  EXPECT_EQ(run.modules.at("relay").iterations, 120u);
  // The output folder is the run's working folder: the recorder, report and trace are there.
  EXPECT_TRUE(QFile::exists(out + "/pipeline.report.json"));
  EXPECT_TRUE(QFile::exists(out + "/pipeline.trace.json"));
  EXPECT_TRUE(QFile::exists(out + "/out/demo/trajectory.csv"));  // the recorder's relative file
  EXPECT_EQ(window_->runController()->traceFile(), out + "/pipeline.trace.json");
  EXPECT_FALSE(window_->runController()->runId().isEmpty());
  ASSERT_TRUE(window_->lastRun().has_value());
  EXPECT_EQ(window_->lastRun()->modules.at("relay").iterations, 120);

  // The choices are remembered for this file.
  runMenu("Run\u2026");
  dialog = runDialog();
  ASSERT_NE(dialog, nullptr);
  EXPECT_EQ(dialog->iterations()->value(), 120);
  EXPECT_EQ(dialog->outputFolder()->text(), out);
  EXPECT_TRUE(dialog->trace()->isChecked());
  dialog->reject();
}

TEST_F(EditorRuns, AThreeHostLaunchIsFollowedLiveWithEveryHostsModules) {
  ASSERT_TRUE(window_->openFile(copyExample("examples/pipeline_3hosts/pipeline_3hosts.xml")));
  runMenu("Launch on hosts");
  RunDialog* dialog = runDialog();
  ASSERT_NE(dialog, nullptr);
  EXPECT_TRUE(dialog->hostsButton()->isChecked());
  EXPECT_EQ(dialog->backend()->currentText(), "local");
  typeInto(dialog->iterations(), "2000");  // about 3 s: statistics come while it runs
  EXPECT_TRUE(dialog->commandLineView()->toPlainText().contains(" launch ")) << log();
  EXPECT_TRUE(dialog->commandLineView()->toPlainText().contains("--backend local"));

  // Which hosts' modules were seen part way, while the launch ran.
  std::set<std::string> hostsSeen;
  std::size_t hostsListed = 0;
  QObject::connect(window_->runController()->live(), &LiveRunModel::changed, window_.get(), [&] {
    const LiveRun& run = window_->runController()->live()->run();
    if (run.phase != LiveRun::Phase::Running) return;
    hostsListed = std::max(hostsListed, run.hosts.size());
    for (const auto& [id, module] : run.modules) {
      if (module.iterations > 0 && module.iterations < 2000) hostsSeen.insert(module.host);
    }
  });
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  clickOk(dialog);
  ASSERT_TRUE(window_->running()) << log();
  ASSERT_TRUE(finished.wait(180000)) << log();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 0) << log();
  EXPECT_EQ(hostsListed, 3u);
  EXPECT_EQ(hostsSeen, (std::set<std::string>{"a", "b", "c"})) << log();
  const LiveRun& run = window_->runController()->live()->run();
  EXPECT_EQ(run.modules.size(), 5u);
  EXPECT_EQ(run.modules.at("springs").host, "b");
  EXPECT_TRUE(status().startsWith("Finished: ")) << status().toStdString();
}

TEST_F(EditorRuns, AttachesToARunStartedOutsideShowsAModuleLogAndStopsIt) {
  const QString file = write("endless.xml", kEndlessApp);
  outside_.setWorkingDirectory(dir_.path());
  outside_.start(binDir() + "/vrflow",
                 {"run", file, "--packages", testPackages(), "--no-progress"});
  ASSERT_TRUE(outside_.waitForStarted());
  // Registered once it runs.
  for (int i = 0; i < 300 && listRuns().isEmpty(); ++i) QTest::qWait(100);
  ASSERT_EQ(listRuns().size(), 1);
  ASSERT_TRUE(window_->openFile(file));

  runMenu("Attach to a run");
  auto* dialog = window_->findChild<AttachDialog*>();
  ASSERT_NE(dialog, nullptr);
  ASSERT_EQ(dialog->table()->rowCount(), 1);
  const QString id = dialog->table()->item(0, 0)->text();
  EXPECT_TRUE(id.startsWith("endless-")) << id.toStdString();
  QTest::mouseClick(dialog->table()->viewport(), Qt::LeftButton, {},
                    dialog->table()->visualItemRect(dialog->table()->item(0, 0)).center());
  EXPECT_EQ(dialog->chosenRun(), id);
  QSignalSpy rates(window_.get(), &MainWindow::liveRatesUpdated);
  clickOk(dialog);
  ASSERT_TRUE(window_->running()) << log();
  EXPECT_TRUE(window_->runController()->attached());
  EXPECT_EQ(window_->runController()->runId(), id);
  ASSERT_TRUE(rates.wait(30000)) << log();
  EXPECT_GT(window_->liveRates().at("relay"), 0.0);
  EXPECT_TRUE(status().startsWith("Running: ")) << status().toStdString();

  // The chatter's log, from the Run menu with the node selected.
  window_->canvas()->selectOnly({"chatter"});
  runMenu("Show log");
  LogView* logView = window_->moduleLog();
  for (int i = 0; i < 100 && !logView->toPlainText().contains("err 3"); ++i) QTest::qWait(100);
  EXPECT_TRUE(logView->toPlainText().contains("out 1")) << logView->toPlainText().toStdString();
  EXPECT_TRUE(logView->toPlainText().contains("err 3")) << logView->toPlainText().toStdString();
  EXPECT_TRUE(logView->following());

  // Stop from the editor: `vrflow stop` ends the outside run, the editor shows why.
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  runMenu("Stop");
  ASSERT_TRUE(finished.wait(60000)) << log();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 130) << log();
  ASSERT_TRUE(outside_.state() == QProcess::NotRunning || outside_.waitForFinished(30000));
  EXPECT_EQ(outside_.exitCode(), 130);
  EXPECT_TRUE(status().startsWith("Stopped")) << status().toStdString();
  for (int i = 0; i < 100 && logView->following(); ++i) QTest::qWait(100);
  EXPECT_FALSE(logView->following());
}

TEST_F(EditorRuns, AFailingHostEndsTheLaunchAndTheStatusBarSaysWhy) {
  ASSERT_TRUE(window_->openFile(write("failing.xml", kFailingHostApp)));
  runMenu("Launch on hosts");
  RunDialog* dialog = runDialog();
  ASSERT_NE(dialog, nullptr);
  typeInto(dialog->iterations(), "50");
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  clickOk(dialog);
  ASSERT_TRUE(finished.wait(180000)) << log();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 1) << log();
  EXPECT_TRUE(status().startsWith("Failed")) << status().toStdString();
  EXPECT_TRUE(status().contains("crash")) << status().toStdString();
  EXPECT_TRUE(status().contains("[exit 1]")) << status().toStdString();
  QTest::qWait(1500);
  EXPECT_TRUE(status().startsWith("Failed")) << status().toStdString();
}

TEST_F(EditorRuns, TheScriptedLaunchWritesTheWindowAndExitsAsTheLaunchDid) {
  const QString file = copyExample("examples/pipeline_3hosts/pipeline_3hosts.xml");
  const QString shot = dir_.filePath("launch.png");
  QProcess editor;
  QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
  env.insert("QT_QPA_PLATFORM", "offscreen");
  editor.setProcessEnvironment(env);
  editor.start(binDir() + "/vrflow-editor",
               {file, "--launch", "local", "--iterations", "200", "--screenshot", shot});
  ASSERT_TRUE(editor.waitForFinished(180000));
  EXPECT_EQ(editor.exitCode(), 0) << editor.readAllStandardError().toStdString();
  QImage image(shot);
  ASSERT_FALSE(image.isNull());
  EXPECT_GE(image.width(), 800);
  if (!qEnvironmentVariableIsEmpty("VRFLOW_KEEP_SHOTS"))
    QFile::copy(shot, qgetenv("VRFLOW_KEEP_SHOTS") + "/launch.png");

  // A launch that fails: the editor's exit status is the launch's.
  const QString failing = write("failing.xml", kFailingHostApp);
  editor.start(binDir() + "/vrflow-editor",
               {failing, "--launch", "local", "--iterations", "50", "--packages", testPackages(),
                "--screenshot", dir_.filePath("failing.png")});
  ASSERT_TRUE(editor.waitForFinished(180000));
  EXPECT_EQ(editor.exitCode(), 1) << editor.readAllStandardError().toStdString();
  EXPECT_FALSE(QImage(dir_.filePath("failing.png")).isNull());
  if (!qEnvironmentVariableIsEmpty("VRFLOW_KEEP_SHOTS"))
    QFile::copy(dir_.filePath("failing.png"), qgetenv("VRFLOW_KEEP_SHOTS") + "/failing.png");
}

}  // namespace
}  // namespace vrflow::editor::gui
