// The editor's window driven like a user would, offscreen: palette, canvas, properties, hosts,
// problems, files, runs.
#include <gtest/gtest.h>

#include <QApplication>
#include <QClipboard>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QDropEvent>
#include <QFile>
#include <QImage>
#include <QListWidget>
#include <QMimeData>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QUndoStack>
#include <QWheelEvent>
#include <filesystem>
#include <memory>

#include "main_window.hpp"
#include "offscreen_app.hpp"
#include "vrflow/app/writer.hpp"

namespace vrflow::editor::gui {
namespace {

namespace fs = std::filesystem;

QString sourceDir() {
  return QString(VRFLOW_TEST_SOURCE_DIR);
}

// Records what the window would show in dialogs, and answers for the user.
class RecordingReporter : public Reporter {
 public:
  void error(QWidget*, const QString& title, const QString& text) override {
    errors << title + ": " + text;
  }
  void warning(QWidget*, const QString& title, const QString& text) override {
    warnings << title + ": " + text;
  }
  Choice askToSave(QWidget*, const QString& text) override {
    questions << text;
    return answer;
  }
  QString fileName(QWidget*, bool, const QString&) override { return nextFile; }
  bool newHost(QWidget*, QString& id, QString& address) override {
    id = "far";
    address = "10.0.0.9";
    return true;
  }
  QStringList errors, warnings, questions;
  Choice answer = Choice::Cancel;
  QString nextFile;
};

class EditorWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_window_tests"); }

  void SetUp() override {
    ASSERT_TRUE(dir_.isValid());
    EditorOptions options;
    options.settingsFile = dir_.filePath("settings.ini");
    options.reporter = &reporter_;
    options.packageDirs.push_back(
        (fs::path(QCoreApplication::applicationDirPath().toStdString()) / ".." / "test-packages")
            .string());
    window_ = std::make_unique<MainWindow>(options);
    window_->resize(1400, 860);
    window_->show();
    QApplication::processEvents();
  }

  const app::Application& app() const { return window_->application(); }
  Canvas* canvas() const { return window_->canvas(); }

  void mouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    sendMouse(canvas(), type, pos, button, buttons);
  }

  // Presses the left button at one scene point, moves, releases at another.
  void drag(QPointF fromScene, QPointF toScene) {
    const QPoint a = canvas()->mapFromScene(fromScene);
    const QPoint b = canvas()->mapFromScene(toScene);
    mouse(QEvent::MouseButtonPress, a, Qt::LeftButton, Qt::LeftButton);
    mouse(QEvent::MouseMove, (a + b) / 2, Qt::NoButton, Qt::LeftButton);
    mouse(QEvent::MouseMove, b, Qt::NoButton, Qt::LeftButton);
    mouse(QEvent::MouseButtonRelease, b, Qt::LeftButton, Qt::NoButton);
    QApplication::processEvents();
  }

  // Drops `mime` on the canvas at a scene point, as a drag from a panel ends.
  void drop(QMimeData* mime, QPointF scenePos) {
    QWidget* viewport = canvas()->viewport();
    const QPoint at = canvas()->mapFromScene(scenePos);
    QDragEnterEvent enter(at, Qt::CopyAction, mime, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(viewport, &enter);
    QDragMoveEvent move(at, Qt::CopyAction, mime, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(viewport, &move);
    // Offered as a move too: the canvas must take a copy, or the panel would lose the row.
    QDropEvent dropped(QPointF(at), Qt::CopyAction | Qt::MoveAction, mime, Qt::LeftButton,
                       Qt::NoModifier);
    dropped.setDropAction(Qt::MoveAction);
    QApplication::sendEvent(viewport, &dropped);
    EXPECT_TRUE(dropped.isAccepted());
    EXPECT_EQ(dropped.dropAction(), Qt::CopyAction);
    QApplication::processEvents();
  }

  void dropFromPalette(const QString& spec, QPointF scenePos) {
    auto* tree = static_cast<PaletteTree*>(window_->palette()->tree());
    QTreeWidgetItem* item = window_->palette()->findEntry(spec);
    ASSERT_NE(item, nullptr) << spec.toStdString();
    std::unique_ptr<QMimeData> mime(tree->dragData({item}));
    ASSERT_NE(mime, nullptr);
    drop(mime.get(), scenePos);
  }

  // points at (0,0) and spring at (300,0), both added from the palette.
  void pointsAndSpring() {
    dropFromPalette("module core points", {0, 0});
    dropFromPalette("module core spring", {300, 0});
    ASSERT_EQ(app().modules.size(), 2u);
  }

  void dragConnect(const std::string& from, const std::string& to) {
    const auto a = app::parseEndpoint(from);
    const auto b = app::parseEndpoint(to);
    drag(canvas()->portScenePos(a->node, a->port), canvas()->portScenePos(b->node, b->port));
  }

  std::string readFile(const QString& path) {
    QFile file(path);
    EXPECT_TRUE(file.open(QIODevice::ReadOnly)) << path.toStdString();
    return file.readAll().toStdString();
  }

  QTemporaryDir dir_;
  RecordingReporter reporter_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(EditorWindow, PaletteListsEveryInstalledTypeGroupedAndSearchable) {
  Palette* palette = window_->palette();
  EXPECT_NE(palette->findEntry("module core points"), nullptr);
  EXPECT_NE(palette->findEntry("module testing crash"), nullptr);  // from --packages
  EXPECT_NE(palette->findEntry("filter merge"), nullptr);
  EXPECT_EQ(palette->findEntry("module core points")->parent()->text(0).left(9), "Animators");
  palette->setFilterText("spring");
  EXPECT_FALSE(palette->findEntry("module core spring")->isHidden());
  EXPECT_TRUE(palette->findEntry("module core points")->isHidden());
}

TEST_F(EditorWindow, AddsNodesFromThePaletteAndUndoesAndRedoes) {
  dropFromPalette("module core points", {100, 50});
  ASSERT_EQ(app().modules.size(), 1u);
  EXPECT_EQ(app().modules[0].id, "points");
  const auto* pos = app::findEditorNode(app(), "points");
  ASSERT_NE(pos, nullptr);
  EXPECT_NEAR(pos->x, 100, 10);
  EXPECT_NEAR(pos->y, 50, 10);
  EXPECT_NE(canvas()->nodeItem("points"), nullptr);
  // A filter is a rhombus: its shape does not hold its bounding box's corner.
  dropFromPalette("filter merge", {400, 50});
  ASSERT_EQ(app().filters.size(), 1u);
  NodeItem* merge = canvas()->nodeItem("merge");
  ASSERT_NE(merge, nullptr);
  EXPECT_FALSE(merge->shape().contains(QPointF(2, 2)));
  EXPECT_TRUE(
      merge->shape().contains(QPointF(merge->size().width() / 2, merge->size().height() / 2)));
  // Double click in the palette adds at the centre of the view.
  auto* tree = window_->palette()->tree();
  QTreeWidgetItem* item = window_->palette()->findEntry("module core relay");
  tree->scrollToItem(item);
  QTest::mouseClick(tree->viewport(), Qt::LeftButton, {}, tree->visualItemRect(item).center());
  QTest::mouseDClick(tree->viewport(), Qt::LeftButton, {}, tree->visualItemRect(item).center());
  EXPECT_NE(app::findModule(app(), "relay"), nullptr);
  EXPECT_TRUE(window_->modified());

  window_->undoStack()->undo();
  EXPECT_EQ(app::findModule(app(), "relay"), nullptr);
  window_->undoStack()->undo();
  EXPECT_TRUE(app().filters.empty());
  window_->undoStack()->undo();
  EXPECT_TRUE(app().modules.empty());
  EXPECT_EQ(canvas()->nodeItem("points"), nullptr);
  EXPECT_FALSE(window_->modified());
  window_->undoStack()->redo();
  EXPECT_EQ(app().modules.size(), 1u);
  EXPECT_NE(canvas()->nodeItem("points"), nullptr);
}

TEST_F(EditorWindow, ConnectsCompatiblePortsByDragAndUndoesAndRedoes) {
  pointsAndSpring();
  dragConnect("points.objects", "spring.objects");
  ASSERT_EQ(app().connections.size(), 1u);
  EXPECT_EQ(app::toString(app().connections[0].to), "spring.objects");
  ASSERT_NE(canvas()->connectionItem(0), nullptr);
  EXPECT_EQ(canvas()->connectionItem(0)->color(), colorOfData("objects"));
  // Dragging from the input end works too.
  dragConnect("points.events", "spring.forces");
  ASSERT_EQ(app().connections.size(), 2u);
  EXPECT_EQ(app::toString(app().connections[1].from), "spring.forces");
  window_->undoStack()->undo();
  window_->undoStack()->undo();
  EXPECT_TRUE(app().connections.empty());
  EXPECT_EQ(canvas()->connectionItem(0), nullptr);
  window_->undoStack()->redo();
  EXPECT_EQ(app().connections.size(), 1u);
  window_->undoStack()->redo();
  EXPECT_EQ(app().connections.size(), 2u);
}

TEST_F(EditorWindow, RefusesAnIncompatibleConnectionSayingWhy) {
  pointsAndSpring();
  const int edits = window_->undoStack()->count();
  dragConnect("points.objects", "points.events");  // objects into an events input
  EXPECT_TRUE(app().connections.empty());
  EXPECT_TRUE(window_->canvas()->lastRefusal().contains("port data types differ"))
      << window_->canvas()->lastRefusal().toStdString();
  dragConnect("points.objects", "spring.forces");  // output to output
  EXPECT_TRUE(app().connections.empty());
  EXPECT_TRUE(window_->canvas()->lastRefusal().contains("outputs"))
      << window_->canvas()->lastRefusal().toStdString();
  EXPECT_EQ(window_->undoStack()->count(), edits);  // nothing to undo from a refusal
  // Undo then takes back the last real edit, and redo restores it.
  window_->undoStack()->undo();
  EXPECT_EQ(app().modules.size(), 1u);
  window_->undoStack()->redo();
  EXPECT_EQ(app().modules.size(), 2u);
}

TEST_F(EditorWindow, MovesNodesByDragAndUndoes) {
  pointsAndSpring();
  canvas()->selectOnly({"spring"});
  const QPointF header = canvas()->nodeItem("spring")->scenePos() + QPointF(60, 10);
  drag(header, header + QPointF(100, 60));
  const auto* pos = app::findEditorNode(app(), "spring");
  ASSERT_NE(pos, nullptr);
  EXPECT_NEAR(pos->x, 400, 10);
  EXPECT_NEAR(pos->y, 60, 10);
  window_->undoStack()->undo();
  EXPECT_NEAR(app::findEditorNode(app(), "spring")->x, 300, 10);
  EXPECT_NEAR(canvas()->nodeItem("spring")->pos().x(), 300, 10);
}

TEST_F(EditorWindow, ZoomsPansAndSelectsWithARubberBand) {
  pointsAndSpring();
  canvas()->resetTransform();
  canvas()->centerOn(200, 50);
  QApplication::processEvents();
  const QPoint centre = canvas()->viewport()->rect().center();
  QWheelEvent wheel(QPointF(centre), canvas()->viewport()->mapToGlobal(QPointF(centre)), QPoint(),
                    QPoint(0, 240), Qt::NoButton, Qt::NoModifier, Qt::NoScrollPhase, false);
  QApplication::sendEvent(canvas()->viewport(), &wheel);
  EXPECT_GT(canvas()->transform().m11(), 1.2);
  // Middle button drag pans.
  const QPointF before = canvas()->mapToScene(centre);
  mouse(QEvent::MouseButtonPress, centre, Qt::MiddleButton, Qt::MiddleButton);
  mouse(QEvent::MouseMove, centre + QPoint(80, 40), Qt::NoButton, Qt::MiddleButton);
  mouse(QEvent::MouseButtonRelease, centre + QPoint(80, 40), Qt::MiddleButton, Qt::NoButton);
  EXPECT_GT(QLineF(before, canvas()->mapToScene(centre)).length(), 20);
  // A rubber band from empty space around both nodes selects both.
  canvas()->resetTransform();
  canvas()->centerOn(200, 50);
  QApplication::processEvents();
  canvas()->selectOnly({});
  drag(QPointF(-40, -60), QPointF(560, 200));
  EXPECT_EQ(canvas()->selectedNodes(), (std::vector<std::string>{"points", "spring"}));
  // Nothing moved: a rubber band is not an edit.
  EXPECT_EQ(window_->undoStack()->count(), 2);
}

TEST_F(EditorWindow, EditsAParameterAndInitialMessagesInThePropertiesPanel) {
  pointsAndSpring();
  canvas()->selectOnly({"spring"});
  auto* stiffness =
      qobject_cast<QDoubleSpinBox*>(window_->properties()->parameterWidget("stiffness"));
  ASSERT_NE(stiffness, nullptr);
  EXPECT_DOUBLE_EQ(stiffness->value(), 50);  // the manifest's default
  EXPECT_TRUE(stiffness->toolTip().contains("Spring stiffness"));
  stiffness->selectAll();
  QTest::keyClicks(stiffness, "123.5");
  QTest::keyClick(stiffness, Qt::Key_Return);
  EXPECT_EQ(app::paramString(app::findModule(app(), "spring")->params, "stiffness", ""), "123.5");
  window_->undoStack()->undo();
  EXPECT_EQ(app::findParam(app::findModule(app(), "spring")->params, "stiffness"), nullptr);
  window_->undoStack()->redo();
  EXPECT_EQ(app::paramString(app::findModule(app(), "spring")->params, "stiffness", ""), "123.5");
  // Leaving a field unchanged writes nothing (an unset parameter stays unset).
  auto* damping = qobject_cast<QDoubleSpinBox*>(window_->properties()->parameterWidget("damping"));
  ASSERT_NE(damping, nullptr);
  const int edits = window_->undoStack()->count();
  Q_EMIT damping->editingFinished();
  EXPECT_EQ(window_->undoStack()->count(), edits);
  EXPECT_EQ(app::findParam(app::findModule(app(), "spring")->params, "damping"), nullptr);
  // Other widget types: a vec3 for gravity's g, an int with range for points' count.
  canvas()->selectOnly({"points"});
  auto* count = qobject_cast<QSpinBox*>(window_->properties()->parameterWidget("count"));
  ASSERT_NE(count, nullptr);
  EXPECT_EQ(count->minimum(), 1);
  EXPECT_EQ(count->maximum(), 100000);
  // The vec3 of gravity: three numbers, written as the manifest writes them.
  dropFromPalette("module core gravity", {0, 300});
  canvas()->selectOnly({"gravity"});
  QWidget* g = window_->properties()->parameterWidget("g");
  ASSERT_NE(g, nullptr);
  auto* gy = g->findChild<QDoubleSpinBox*>("component1");
  ASSERT_NE(gy, nullptr);
  EXPECT_DOUBLE_EQ(gy->value(), -9.81);
  gy->selectAll();
  QTest::keyClicks(gy, "-3.5");
  QTest::keyClick(gy, Qt::Key_Return);
  EXPECT_EQ(app::paramString(app::findModule(app(), "gravity")->params, "g", ""), "0 -3.5 0");
  canvas()->selectOnly({"points"});
  auto* initial = qobject_cast<QSpinBox*>(window_->properties()->initialMessagesWidget("events"));
  ASSERT_NE(initial, nullptr);
  initial->selectAll();
  QTest::keyClicks(initial, "1");
  QTest::keyClick(initial, Qt::Key_Return);
  EXPECT_EQ(app::inputConfigOrDefault(*app::findModule(app(), "points"), "events").initialMessages,
            1);
}

TEST_F(EditorWindow, AssignsHostsFromThePanelThePropertiesAndByDrop) {
  pointsAndSpring();
  auto buttons = window_->hosts()->findChildren<QPushButton*>();
  auto button = [&](const QString& text) {
    for (auto* b : buttons) {
      if (b->text() == text) return b;
    }
    return static_cast<QPushButton*>(nullptr);
  };
  QTest::mouseClick(button("Add"), Qt::LeftButton);
  ASSERT_EQ(app().hosts.size(), 2u);
  EXPECT_EQ(app().hosts[1].id, "far");
  EXPECT_EQ(window_->hosts()->table()->rowCount(), 2);
  // Selection-wide: select spring, choose host row "far", "Assign selection".
  canvas()->selectOnly({"spring"});
  window_->hosts()->table()->setCurrentCell(1, 1);
  QTest::mouseClick(button("Assign selection"), Qt::LeftButton);
  EXPECT_EQ(app::findModule(app(), "spring")->host, "far");
  window_->undoStack()->undo();
  EXPECT_EQ(app::findModule(app(), "spring")->host, "localhost");
  window_->undoStack()->redo();
  EXPECT_EQ(app::findModule(app(), "spring")->host, "far");
  // The properties panel's host box.
  canvas()->selectOnly({"points"});
  auto* hostBox = window_->properties()->findChild<QComboBox*>("host");
  ASSERT_NE(hostBox, nullptr);
  hostBox->setCurrentIndex(1);
  Q_EMIT hostBox->activated(1);
  EXPECT_EQ(app::findModule(app(), "points")->host, "far");
  // Dragging a host row onto a node.
  QMimeData mime;
  mime.setData(kHostMime, "localhost");
  drop(&mime, canvas()->nodeItem("points")->scenePos() + QPointF(60, 20));
  EXPECT_EQ(app::findModule(app(), "points")->host, "localhost");
  // The saved file says it.
  EXPECT_NE(app::saveApplication(app()).find("type=\"spring\" host=\"far\""), std::string::npos);
  // Renaming a host and changing its address in the table; the nodes follow.
  window_->hosts()->table()->item(1, 1)->setText("gpu");
  QApplication::processEvents();
  ASSERT_EQ(app().hosts[1].id, "gpu");
  EXPECT_EQ(app::findModule(app(), "spring")->host, "gpu");
  window_->hosts()->table()->item(1, 2)->setText("10.0.0.10");
  QApplication::processEvents();
  EXPECT_EQ(app().hosts[1].address, "10.0.0.10");
  // A name already taken is refused and the table shows the real name again.
  window_->hosts()->table()->item(1, 1)->setText("localhost");
  QApplication::processEvents();
  EXPECT_EQ(app().hosts[1].id, "gpu");
  EXPECT_EQ(window_->hosts()->table()->item(1, 1)->text(), "gpu");
}

TEST_F(EditorWindow, DeletesDuplicatesCopiesAndPastes) {
  pointsAndSpring();
  dragConnect("points.objects", "spring.objects");
  canvas()->selectOnly({"points", "spring"});
  window_->duplicateSelection();
  EXPECT_EQ(app().modules.size(), 4u);
  EXPECT_EQ(app().connections.size(), 2u);
  EXPECT_EQ(canvas()->selectedNodes(), (std::vector<std::string>{"points2", "spring2"}));
  window_->copySelection();
  EXPECT_TRUE(QApplication::clipboard()->text().contains("<application"));
  window_->paste();
  EXPECT_EQ(app().modules.size(), 6u);
  canvas()->setFocus();
  QTest::keyClick(canvas(), Qt::Key_Delete);
  EXPECT_EQ(app().modules.size(), 4u);
  window_->undoStack()->undo();
  EXPECT_EQ(app().modules.size(), 6u);
}

TEST_F(EditorWindow, SavesAndReloadsAnEqualModel) {
  pointsAndSpring();
  dragConnect("points.objects", "spring.objects");
  dragConnect("spring.forces", "points.events");
  window_->apply(setInitialMessages(app(), "points", "events", 1));
  window_->apply(setParameter(app(), "spring", "damping", "0.25"));
  const QString file = dir_.filePath("saved.xml");
  ASSERT_TRUE(window_->saveAs(file));
  EXPECT_FALSE(window_->modified());
  EXPECT_TRUE(window_->recentFiles().contains(QFileInfo(file).absoluteFilePath()));
  const std::string saved = app::saveApplication(app());
  EXPECT_EQ(readFile(file), saved);

  MainWindow other(EditorOptions{{}, dir_.filePath("other.ini"), &reporter_, {}, true});
  ASSERT_TRUE(other.openFile(file));
  EXPECT_EQ(app::saveApplication(other.application()), saved);
  EXPECT_EQ(other.application().connections.size(), 2u);
  EXPECT_NE(app::findEditorNode(other.application(), "spring"), nullptr);
  EXPECT_TRUE(reporter_.errors.isEmpty()) << reporter_.errors.join("\n").toStdString();
}

TEST_F(EditorWindow, EveryExampleOpensAndSavesUnchangedToTheSameBytes) {
  int count = 0;
  for (const auto& entry :
       fs::recursive_directory_iterator(fs::path(VRFLOW_TEST_SOURCE_DIR) / "examples")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".xml" || name.ends_with(".vrc.xml") ||
        name == "vrflow-package.xml")
      continue;
    const QString path = QString::fromStdString(entry.path().string());
    ASSERT_TRUE(window_->openFile(path)) << name << reporter_.errors.join("\n").toStdString();
    EXPECT_FALSE(window_->modified());
    EXPECT_FALSE(app().modules.empty() && app().instances.empty()) << name;
    const QString copy = dir_.filePath(QString::fromStdString(name));
    ASSERT_TRUE(window_->saveAs(copy));
    EXPECT_EQ(readFile(copy), readFile(path)) << name;
    ++count;
  }
  EXPECT_GE(count, 5);
  EXPECT_TRUE(reporter_.errors.isEmpty()) << reporter_.errors.join("\n").toStdString();
}

// multi_rate.xml names its own package folder (<packages path="."/>): the editor, started
// without it, learns the package `multirate` when it opens the file.
TEST_F(EditorWindow, OpeningAFileAddsItsPackageFoldersToThePalette) {
  const QString path = sourceDir() + "/examples/multi_rate/multi_rate.xml";
  ASSERT_TRUE(window_->openFile(path)) << reporter_.errors.join("\n").toStdString();
  for (const auto& problem : window_->problems()) {
    EXPECT_EQ(problem.message.find("unknown package"), std::string::npos) << problem.message;
  }
}

TEST_F(EditorWindow, ShowsADeadlockCycleAsAnErrorOnCanvasAndInTheProblems) {
  pointsAndSpring();
  dragConnect("points.objects", "spring.objects");
  dragConnect("spring.forces", "points.events");
  ASSERT_EQ(app().connections.size(), 2u);
  const auto& problems = window_->problems();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].severity, app::Diagnostic::Error);
  EXPECT_EQ(problems[0].cycle.size(), 2u);
  EXPECT_EQ(canvas()->connectionItem(0)->problem(), 3);
  EXPECT_EQ(canvas()->connectionItem(1)->problem(), 3);
  ASSERT_EQ(window_->problemList()->count(), 1);
  EXPECT_TRUE(window_->problemList()->item(0)->text().contains("would deadlock"));
  Q_EMIT window_->problemList()->itemActivated(window_->problemList()->item(0));
  EXPECT_FALSE(canvas()->selectedNodes().empty());
  // An initial message breaks the cycle.
  window_->apply(setInitialMessages(app(), "points", "events", 1));
  EXPECT_TRUE(window_->problems().empty());
  EXPECT_EQ(canvas()->connectionItem(0)->problem(), 0);
  EXPECT_EQ(window_->problemList()->count(), 0);
  // A node with a problem carries a marker with the reason as tooltip.
  window_->apply(setParameter(app(), "spring", "stiffness", "-3"));
  EXPECT_EQ(canvas()->nodeItem("spring")->problemLevel(), 2);
  EXPECT_TRUE(canvas()->nodeItem("spring")->toolTip().contains("stiffness"));
}

TEST_F(EditorWindow, NodesOfUnknownTypesKeepThePortsTheirConnectionsName) {
  const QString file = dir_.filePath("unknown.xml");
  {
    QFile out(file);
    ASSERT_TRUE(out.open(QIODevice::WriteOnly));
    out.write(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"u\" version=\"1\">\n"
        "  <modules>\n    <module id=\"a\" package=\"nowhere\" type=\"thing\"/>\n"
        "    <module id=\"r\" package=\"core\" type=\"recorder\"/>\n  </modules>\n"
        "  <connections>\n    <connection from=\"a.out\" to=\"r.in\"/>\n  </connections>\n"
        "</application>\n");
  }
  ASSERT_TRUE(window_->openFile(file));
  EXPECT_NE(canvas()->portItem("a", "out"), nullptr);
  EXPECT_NE(canvas()->connectionItem(0), nullptr);
  EXPECT_EQ(canvas()->nodeItem("a")->problemLevel(), 2);  // unknown package
}

TEST_F(EditorWindow, AMalformedFileGivesAClearMessageAndKeepsTheDocument) {
  pointsAndSpring();
  const QString bad = dir_.filePath("bad.xml");
  {
    QFile file(bad);
    ASSERT_TRUE(file.open(QIODevice::WriteOnly));
    file.write(
        "<?xml version=\"1.0\"?>\n<application name=\"x\" version=\"1\">\n  <modules>\n    <module "
        "id=\"a\"\n");
  }
  EXPECT_FALSE(window_->openFile(bad));
  ASSERT_EQ(reporter_.errors.size(), 1);
  EXPECT_TRUE(reporter_.errors[0].contains("bad.xml")) << reporter_.errors[0].toStdString();
  EXPECT_TRUE(reporter_.errors[0].contains("error:")) << reporter_.errors[0].toStdString();
  EXPECT_EQ(app().modules.size(), 2u);  // what was there stays
  EXPECT_FALSE(window_->openFile(dir_.filePath("missing.xml")));
  EXPECT_EQ(reporter_.errors.size(), 2);
  // A manifest is not an application either.
  EXPECT_FALSE(window_->openFile(sourceDir() + "/runtime/modules/core/vrflow-package.xml"));
  ASSERT_EQ(reporter_.errors.size(), 3);
  EXPECT_TRUE(reporter_.errors[2].contains("root element must be <application>"))
      << reporter_.errors[2].toStdString();
  EXPECT_EQ(app().modules.size(), 2u);
}

TEST_F(EditorWindow, WarnsBeforeLosingUnsavedChanges) {
  EXPECT_TRUE(window_->maybeSave());  // nothing to lose
  EXPECT_TRUE(reporter_.questions.isEmpty());
  pointsAndSpring();
  reporter_.answer = Reporter::Choice::Cancel;
  EXPECT_FALSE(window_->maybeSave());
  EXPECT_EQ(reporter_.questions.size(), 1);
  reporter_.answer = Reporter::Choice::Save;
  reporter_.nextFile = dir_.filePath("kept.xml");
  EXPECT_TRUE(window_->maybeSave());
  EXPECT_TRUE(QFile::exists(reporter_.nextFile));
  EXPECT_FALSE(window_->modified());
}

TEST_F(EditorWindow, AutomaticLayoutPlacesNodesLeftToRightAndUndoes) {
  dropFromPalette("module core source", {0, 0});
  dropFromPalette("module core relay", {0, 200});
  dropFromPalette("module core recorder", {0, 400});
  dragConnect("source.out", "relay.in");
  dragConnect("relay.out", "recorder.in");
  window_->autoLayout();
  const double a = app::findEditorNode(app(), "source")->x;
  const double b = app::findEditorNode(app(), "relay")->x;
  const double c = app::findEditorNode(app(), "recorder")->x;
  EXPECT_LT(a, b);
  EXPECT_LT(b, c);
  window_->undoStack()->undo();
  EXPECT_EQ(app::findEditorNode(app(), "relay")->y, 200);
}

TEST_F(EditorWindow, RunsAnApplicationAndShowsWhatTheRunReported) {
  QDir::setCurrent(dir_.path());  // the recorder writes relative to here
  dropFromPalette("module core source", {0, 0});
  dropFromPalette("module core recorder", {300, 0});
  dragConnect("source.out", "recorder.in");
  reporter_.nextFile = dir_.filePath("run.xml");
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  window_->runApplication(25);
  ASSERT_TRUE(finished.wait(60000)) << window_->log()->toPlainText().toStdString();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 0) << window_->log()->toPlainText().toStdString();
  ASSERT_TRUE(window_->lastRun().has_value());
  EXPECT_EQ(window_->lastRun()->modules.at("source").iterations, 25);
  EXPECT_EQ(window_->lastRun()->connections.at(0).messages, 25);
  EXPECT_TRUE(canvas()->connectionItem(0)->label().startsWith("25 msg"));
  EXPECT_TRUE(window_->log()->toPlainText().contains("Run finished"));
}

TEST_F(EditorWindow, ShowsLiveIterationRatesWhileARunGoesOn) {
  QDir::setCurrent(dir_.path());
  // 60 iterations of a relay that waits 25 ms each: the run lasts at least 1.5 s, and the
  // runtime writes its statistics to the event stream every second.
  dropFromPalette("module core source", {0, 0});
  dropFromPalette("module core relay", {300, 0});
  dropFromPalette("module core recorder", {600, 0});
  dragConnect("source.out", "relay.in");
  dragConnect("relay.out", "recorder.in");
  window_->apply(setParameter(app(), "relay", "delay-ms", "25"));
  reporter_.nextFile = dir_.filePath("live.xml");
  QSignalSpy live(window_.get(), &MainWindow::liveRatesUpdated);
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  window_->runApplication(60);
  ASSERT_TRUE(finished.wait(60000)) << window_->log()->toPlainText().toStdString();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 0) << window_->log()->toPlainText().toStdString();
  ASSERT_GE(live.count(), 1) << window_->log()->toPlainText().toStdString();
  EXPECT_EQ(window_->liveRates().count("relay"), 1u);
  EXPECT_EQ(window_->liveRates().count("source"), 1u);
  EXPECT_GT(window_->liveRates().at("relay"), 0.0);
  // The rates come from the run's event stream (docs/events.md), not from its progress line.
  EXPECT_TRUE(window_->log()->toPlainText().contains("--events -"));
  EXPECT_FALSE(window_->log()->toPlainText().contains("[vrflow "));  // not in the log
  EXPECT_EQ(window_->lastRun()->modules.at("relay").iterations, 60);
}

TEST_F(EditorWindow, StopsARunThatWouldNotEnd) {
  QDir::setCurrent(dir_.path());
  dropFromPalette("module core source", {0, 0});  // count 0: until the run stops
  dropFromPalette("module core relay", {300, 0});
  dropFromPalette("module core recorder", {600, 0});
  dragConnect("source.out", "relay.in");
  dragConnect("relay.out", "recorder.in");
  window_->apply(setParameter(app(), "relay", "delay-ms", "20"));
  reporter_.nextFile = dir_.filePath("endless.xml");
  QSignalSpy live(window_.get(), &MainWindow::liveRatesUpdated);
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  window_->runApplication();
  ASSERT_TRUE(window_->running());
  ASSERT_TRUE(live.wait(30000)) << window_->log()->toPlainText().toStdString();  // it is going
  window_->stopRun();
  ASSERT_TRUE(finished.count() > 0 || finished.wait(30000));
  EXPECT_EQ(finished.at(0).at(0).toInt(), 130) << window_->log()->toPlainText().toStdString();
  EXPECT_FALSE(window_->running());
  EXPECT_TRUE(window_->log()->toPlainText().contains("Run stopped"));
}

TEST_F(EditorWindow, AFailedRunShowsTheFailingModule) {
  QDir::setCurrent(dir_.path());
  dropFromPalette("module core source", {0, 0});
  dropFromPalette("module testing crash", {300, 0});
  dropFromPalette("module core recorder", {600, 0});
  dragConnect("source.out", "crash.in");
  dragConnect("crash.out", "recorder.in");
  reporter_.nextFile = dir_.filePath("crash.xml");
  QSignalSpy finished(window_.get(), &MainWindow::runFinished);
  window_->runApplication(50);
  ASSERT_TRUE(finished.wait(60000)) << window_->log()->toPlainText().toStdString();
  EXPECT_EQ(finished.at(0).at(0).toInt(), 1);
  ASSERT_TRUE(window_->lastRun().has_value());
  EXPECT_EQ(window_->lastRun()->failedModule, "crash");
  EXPECT_EQ(canvas()->selectedNodes(), std::vector<std::string>{"crash"});
  EXPECT_TRUE(window_->log()->toPlainText().contains("module 'crash'"))
      << window_->log()->toPlainText().toStdString();
}

TEST_F(EditorWindow, TheScreenshotCommandRendersTheWindowOffscreen) {
  QProcess editor;
  QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
  env.insert("QT_QPA_PLATFORM", "offscreen");
  editor.setProcessEnvironment(env);
  const QString out = dir_.filePath("shot.png");
  editor.start(QCoreApplication::applicationDirPath() + "/vrflow-editor",
               {sourceDir() + "/examples/pipeline/pipeline.xml", "--screenshot", out});
  ASSERT_TRUE(editor.waitForFinished(60000));
  EXPECT_EQ(editor.exitCode(), 0) << editor.readAllStandardError().toStdString();
  QImage image(out);
  ASSERT_FALSE(image.isNull());
  EXPECT_GE(image.width(), 800);
  // A malformed file: exit 1, the message on stderr.
  const QString bad = dir_.filePath("bad.xml");
  {
    QFile file(bad);
    ASSERT_TRUE(file.open(QIODevice::WriteOnly));
    file.write("<application");
  }
  editor.start(QCoreApplication::applicationDirPath() + "/vrflow-editor",
               {bad, "--screenshot", out + "2"});
  ASSERT_TRUE(editor.waitForFinished(60000));
  EXPECT_EQ(editor.exitCode(), 1);
  EXPECT_TRUE(editor.readAllStandardError().contains("bad.xml"));
}

}  // namespace
}  // namespace vrflow::editor::gui
