// The canvas driven like a user would, offscreen: the scene follows edits item by item, notes
// and frames, fit, drops, initial-message tokens and connections routed around nodes.
#include <gtest/gtest.h>

#include <QAction>
#include <QApplication>
#include <QContextMenuEvent>
#include <QDoubleSpinBox>
#include <QFile>
#include <QMenu>
#include <QMimeData>
#include <QTemporaryDir>
#include <QTest>
#include <QUndoStack>
#include <filesystem>
#include <memory>

#include "main_window.hpp"
#include "offscreen_app.hpp"
#include "vrflow/editor/notes.hpp"

namespace vrflow::editor::gui {
namespace {

namespace fs = std::filesystem;

class CanvasWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_canvas_tests"); }

  void SetUp() override {
    ASSERT_TRUE(dir_.isValid());
    EditorOptions options;
    options.settingsFile = dir_.filePath("settings.ini");
    options.rememberRecent = false;
    options.packageDirs.push_back(
        (fs::path(QCoreApplication::applicationDirPath().toStdString()) / ".." / "test-packages")
            .string());
    window_ = std::make_unique<MainWindow>(options);
    window_->resize(1400, 860);
    window_->show();
    window_->activateWindow();  // in-place text needs an active scene
    QApplication::processEvents();
  }

  // Opens an example by its path under examples/.
  void openExample(const QString& path) {
    ASSERT_TRUE(window_->openFile(QString(VRFLOW_TEST_SOURCE_DIR) + "/examples/" + path));
    QApplication::processEvents();
  }

  // Natural size, centred on a scene point (what the tests' scene coordinates assume).
  void lookAt(QPointF centre) {
    canvas()->resetTransform();
    canvas()->centerOn(centre);
    QApplication::processEvents();
  }

  // Opens application XML written to a file of the test's own.
  void openText(const char* xml) {
    const QString path = dir_.filePath("app.xml");
    QFile file(path);
    ASSERT_TRUE(file.open(QIODevice::WriteOnly));
    file.write(xml);
    file.close();
    ASSERT_TRUE(window_->openFile(path));
    QApplication::processEvents();
  }

  const app::Application& app() const { return window_->application(); }
  Canvas* canvas() const { return window_->canvas(); }
  QPoint at(QPointF scenePos) const { return canvas()->mapFromScene(scenePos); }

  void mouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    sendMouse(canvas(), type, pos, button, buttons);
  }

  // Presses the left button at one scene point, moves in steps, releases at another;
  // `midway` runs while the button is still down.
  void drag(QPointF fromScene, QPointF toScene, const std::function<void()>& midway = {}) {
    const QPoint a = at(fromScene);
    const QPoint b = at(toScene);
    mouse(QEvent::MouseButtonPress, a, Qt::LeftButton, Qt::LeftButton);
    mouse(QEvent::MouseMove, a + (b - a) / 3, Qt::NoButton, Qt::LeftButton);
    if (midway) midway();
    mouse(QEvent::MouseMove, a + (b - a) * 2 / 3, Qt::NoButton, Qt::LeftButton);
    mouse(QEvent::MouseMove, b, Qt::NoButton, Qt::LeftButton);
    mouse(QEvent::MouseButtonRelease, b, Qt::LeftButton, Qt::NoButton);
    QApplication::processEvents();
  }

  // Right-clicks at a scene point and picks `entry` in the menu that pops up.
  void pickFromContextMenu(QPointF scenePos, const QString& entry) {
    const QPoint pos = at(scenePos);
    mouse(QEvent::MouseButtonPress, pos, Qt::RightButton, Qt::RightButton);
    mouse(QEvent::MouseButtonRelease, pos, Qt::RightButton, Qt::NoButton);
    QContextMenuEvent event(QContextMenuEvent::Mouse, pos, canvas()->viewport()->mapToGlobal(pos));
    QApplication::sendEvent(canvas()->viewport(), &event);
    QApplication::processEvents();
    auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget());
    ASSERT_NE(menu, nullptr) << "no menu at " << scenePos.x() << ", " << scenePos.y();
    QAction* found = nullptr;
    for (QAction* action : menu->findChildren<QAction*>()) {
      if (action->text() == entry) found = action;
    }
    ASSERT_NE(found, nullptr) << entry.toStdString();
    EXPECT_TRUE(found->isEnabled()) << entry.toStdString();
    found->trigger();
    menu->close();
    QApplication::processEvents();
  }

  // Lets the deferred commit of an in-place text run.
  static void settle() {
    for (int i = 0; i < 3; ++i) QApplication::processEvents();
  }

  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(CanvasWindow, AnEditOfOneParameterKeepsTheOtherItemsAndTheirSelection) {
  openExample("pipeline/pipeline.xml");
  NodeItem* chain = canvas()->nodeItem("chain");
  NodeItem* gravity = canvas()->nodeItem("gravity");
  ConnectionItem* edge = canvas()->connectionItem(5);  // relay -> recorder
  ASSERT_NE(chain, nullptr);
  ASSERT_NE(edge, nullptr);
  // Select springs by a click on its header, and the relay -> recorder connection beside it.
  const QPointF header = canvas()->nodeItem("springs")->scenePos() + QPointF(60, 10);
  mouse(QEvent::MouseButtonPress, at(header), Qt::LeftButton, Qt::LeftButton);
  mouse(QEvent::MouseButtonRelease, at(header), Qt::LeftButton, Qt::NoButton);
  edge->setSelected(true);
  ASSERT_EQ(canvas()->selectedNodes(), std::vector<std::string>{"springs"});
  const QPointF centre = canvas()->mapToScene(canvas()->viewport()->rect().center());

  auto* stiffness =
      qobject_cast<QDoubleSpinBox*>(window_->properties()->parameterWidget("stiffness"));
  ASSERT_NE(stiffness, nullptr);
  stiffness->selectAll();
  QTest::keyClicks(stiffness, "123");
  QTest::keyClick(stiffness, Qt::Key_Return);
  QApplication::processEvents();
  ASSERT_EQ(app::paramString(app::findModule(app(), "springs")->params, "stiffness", ""), "123");

  EXPECT_EQ(canvas()->nodeItem("chain"), chain);
  EXPECT_EQ(canvas()->nodeItem("gravity"), gravity);
  EXPECT_EQ(canvas()->connectionItem(5), edge);
  EXPECT_TRUE(edge->isSelected());
  EXPECT_EQ(canvas()->selectedNodes(), std::vector<std::string>{"springs"});
  EXPECT_EQ(canvas()->mapToScene(canvas()->viewport()->rect().center()), centre);
  // Undo too changes only what the edit changed.
  window_->undoStack()->undo();
  EXPECT_EQ(canvas()->nodeItem("chain"), chain);
  EXPECT_TRUE(edge->isSelected());
}

TEST_F(CanvasWindow, ADragInProgressSurvivesAnUnrelatedEdit) {
  openExample("pipeline/pipeline.xml");
  canvas()->selectOnly({"recorder"});
  NodeItem* recorder = canvas()->nodeItem("recorder");
  const QPointF start = recorder->scenePos();
  drag(start + QPointF(60, 10), start + QPointF(160, 70), [&] {
    // While the button is down, something else changes the application.
    ASSERT_TRUE(window_->apply(setParameter(app(), "springs", "damping", "0.5")));
  });
  EXPECT_EQ(canvas()->nodeItem("recorder"), recorder);
  const auto* placed = app::findEditorNode(app(), "recorder");
  ASSERT_NE(placed, nullptr);
  EXPECT_NEAR(placed->x, start.x() + 100, 10);
  EXPECT_NEAR(placed->y, start.y() + 60, 10);
  EXPECT_EQ(window_->undoStack()->count(), 2);  // the parameter, then the move
}

TEST_F(CanvasWindow, NotesAreAddedMovedResizedEditedInPlaceAndDeleted) {
  openExample("pipeline/pipeline.xml");
  lookAt({300, 300});
  pickFromContextMenu({0, 350}, "Add note");
  ASSERT_EQ(app().notes.size(), 1u);
  const std::string id = app().notes.front().id;
  NoteItem* note = canvas()->noteItem(id);
  ASSERT_NE(note, nullptr);
  EXPECT_NEAR(note->pos().x(), 0, 2);
  EXPECT_NEAR(note->pos().y(), 350, 2);

  // Moved by dragging its body.
  drag(note->scenePos() + QPointF(30, 30), note->scenePos() + QPointF(130, 80));
  EXPECT_NEAR(app().notes.front().x, 100, 3);
  EXPECT_NEAR(app().notes.front().y, 400, 3);
  EXPECT_EQ(canvas()->noteItem(id), note);
  // Resized by its corner handle.
  const QPointF corner =
      note->scenePos() + QPointF(note->size().width() - 4, note->size().height() - 4);
  drag(corner, corner + QPointF(120, 60));
  EXPECT_NEAR(app().notes.front().width, 200 + 120, 6);
  EXPECT_NEAR(app().notes.front().height, 80 + 60, 6);
  EXPECT_NEAR(app().notes.front().x, 100, 3);  // the corner moved, not the note
  // Its text edited in place: double-click, type, click elsewhere.
  const QPoint text = at(note->scenePos() + QPointF(40, 40));
  QTest::mouseDClick(canvas()->viewport(), Qt::LeftButton, {}, text);
  mouse(QEvent::MouseButtonRelease, text, Qt::LeftButton, Qt::NoButton);  // as a mouse ends it
  QTest::keyClicks(canvas(), "Springs are stiff");
  QTest::mouseClick(canvas()->viewport(), Qt::LeftButton, {}, at({-120, 150}));

  settle();
  EXPECT_EQ(app().notes.front().text, "Springs are stiff");
  EXPECT_EQ(note->text(), "Springs are stiff");
  EXPECT_EQ(window_->undoStack()->undoText(), "Edit note");

  // Deleted with the Delete key, and back with undo.
  note->setSelected(true);
  canvas()->setFocus();
  QTest::keyClick(canvas(), Qt::Key_Delete);
  EXPECT_TRUE(app().notes.empty());
  EXPECT_EQ(canvas()->noteItem(id), nullptr);
  window_->undoStack()->undo();
  ASSERT_EQ(app().notes.size(), 1u);
  EXPECT_EQ(app().notes.front().text, "Springs are stiff");
  // Every step was one edit: add, move, resize, text, delete.
  EXPECT_EQ(window_->undoStack()->index(), 4);
}

TEST_F(CanvasWindow, FramesGoBehindNodesCarryThemAndAreRenamedAndRecoloured) {
  openExample("pipeline/pipeline.xml");
  lookAt({350, 300});
  canvas()->selectOnly({"relay", "recorder"});
  pickFromContextMenu({-50, 450}, "Frame around selection");
  ASSERT_EQ(app().frames.size(), 1u);
  const app::EditorFrame frame = app().frames.front();
  FrameItem* item = canvas()->frameItem(frame.id);
  ASSERT_NE(item, nullptr);
  EXPECT_LT(item->zValue(), canvas()->nodeItem("relay")->zValue());
  EXPECT_LT(item->zValue(), canvas()->connectionItem(0)->zValue());
  EXPECT_TRUE(item->sceneBoundingRect().contains(canvas()->nodeItem("recorder")->sceneBody()));

  // Dragging the frame by its title carries the nodes inside, in one undoable edit.
  canvas()->selectOnly({});
  const QPointF chain = canvas()->nodeItem("chain")->scenePos();
  const QPointF relay = canvas()->nodeItem("relay")->scenePos();
  const QPointF title = item->scenePos() + QPointF(item->size().width() - 40, 8);
  drag(title, title + QPointF(0, 200));
  EXPECT_NEAR(app().frames.front().y, frame.y + 200, 3);
  EXPECT_NEAR(app::findEditorNode(app(), "relay")->y, relay.y() + 200, 3);
  EXPECT_NEAR(app::findEditorNode(app(), "recorder")->y, 400, 3);
  EXPECT_EQ(canvas()->nodeItem("chain")->scenePos(), chain);  // outside: stays
  EXPECT_EQ(window_->undoStack()->undoText(), "Move frame");

  // Renamed in place from its menu, recoloured from its menu.
  const QPointF inside = item->scenePos() + QPointF(10, item->size().height() - 20);
  pickFromContextMenu(inside, "Rename frame");
  QTest::keyClicks(canvas(), "Output");
  QTest::keyClick(canvas(), Qt::Key_Return);
  settle();
  EXPECT_EQ(app().frames.front().title, "Output");
  EXPECT_EQ(item->title(), "Output");
  pickFromContextMenu(inside, "Green");
  EXPECT_EQ(app().frames.front().color, "#4caf50");
  EXPECT_EQ(item->color(), QColor("#4caf50"));
  // Resized by its corner: the nodes stay.
  const QPointF corner =
      item->scenePos() + QPointF(item->size().width() - 4, item->size().height() - 4);
  drag(corner, corner + QPointF(60, 30));
  EXPECT_NEAR(app().frames.front().width, frame.width + 60, 6);
  EXPECT_NEAR(app::findEditorNode(app(), "recorder")->y, 400, 3);

  // A picture of the frame behind its nodes, with a note, for the docs (when asked for).
  if (const QString shot = qEnvironmentVariable("VRFLOW_CANVAS_FRAME_SCREENSHOT");
      !shot.isEmpty()) {
    ASSERT_TRUE(window_->apply(addNote(app(), -150, 330, "The recorder writes\nout/demo/")));
    EXPECT_TRUE(window_->screenshot(shot));
    window_->undoStack()->undo();
  }
  window_->undoStack()->undo();  // resize
  window_->undoStack()->undo();  // colour
  window_->undoStack()->undo();  // title
  window_->undoStack()->undo();  // move
  EXPECT_NEAR(app::findEditorNode(app(), "recorder")->y, 200, 1);
  EXPECT_EQ(canvas()->frameItem(frame.id), item);
  window_->undoStack()->undo();  // add
  EXPECT_TRUE(app().frames.empty());
  EXPECT_EQ(canvas()->frameItem(frame.id), nullptr);
}

TEST_F(CanvasWindow, FitShowsTheWholeRoutedWallAndNeverZoomsPastNaturalSize) {
  openExample("routed_wall/routed_wall.xml");
  canvas()->fitAll();
  const QRectF visible =
      canvas()->mapToScene(canvas()->viewport()->rect()).boundingRect().adjusted(-1, -1, 1, 1);
  ASSERT_FALSE(app().modules.empty());
  for (const auto& id : nodeIds(app())) {
    NodeItem* node = canvas()->nodeItem(id);
    ASSERT_NE(node, nullptr) << id;
    EXPECT_TRUE(visible.contains(node->sceneBody())) << id << " is outside the fitted view";
  }
  EXPECT_LE(canvas()->transform().m11(), 1.0);
  const QString shot = qEnvironmentVariable("VRFLOW_CANVAS_SCREENSHOT");
  if (!shot.isEmpty()) {
    EXPECT_TRUE(window_->screenshot(shot));
  }

  // A small network is shown at its natural size, not blown up.
  openText(R"(<application name="one"><modules>
    <module id="a" package="core" type="relay"/></modules></application>)");
  canvas()->fitAll();
  EXPECT_DOUBLE_EQ(canvas()->transform().m11(), 1.0);
}

TEST_F(CanvasWindow, DroppingANodeKeepsTheViewWhereItWas) {
  openExample("pipeline/pipeline.xml");
  canvas()->resetTransform();
  canvas()->centerOn(200, 50);
  QApplication::processEvents();
  const QPoint centre = canvas()->viewport()->rect().center();
  const QPointF before = canvas()->mapToScene(centre);
  // Near the bottom-right edge of the view, where showing the new node used to scroll.
  const QPoint edge = canvas()->viewport()->rect().bottomRight() - QPoint(60, 40);
  QMimeData mime;
  mime.setData(kNodeMime, "module core relay");
  QDragEnterEvent enter(edge, Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(canvas()->viewport(), &enter);
  QDragMoveEvent move(edge, Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(canvas()->viewport(), &move);
  QDropEvent dropped(QPointF(edge), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(canvas()->viewport(), &dropped);
  QApplication::processEvents();
  ASSERT_NE(canvas()->nodeItem("relay2"), nullptr);
  EXPECT_EQ(canvas()->selectedNodes(), std::vector<std::string>{"relay2"});
  EXPECT_EQ(canvas()->mapToScene(centre), before);
}

TEST_F(CanvasWindow, InitialMessagesAreDrawnAsTokensOnTheirInputs) {
  openExample("pipeline/pipeline.xml");
  PortItem* events = canvas()->portItem("chain", "events");
  ASSERT_NE(events, nullptr);
  EXPECT_EQ(events->tokens(), 1);  // initial-messages="1" in the file
  EXPECT_EQ(canvas()->portItem("springs", "objects")->tokens(), 0);
  const QRectF plain = canvas()->portItem("springs", "objects")->boundingRect();
  EXPECT_GT(events->boundingRect().width(), plain.width());  // room for the token

  canvas()->selectOnly({"chain"});
  ASSERT_TRUE(window_->apply(setInitialMessages(app(), "chain", "events", 5)));
  EXPECT_EQ(canvas()->portItem("chain", "events"), events);  // drawn anew in place
  EXPECT_EQ(events->tokens(), 5);
  window_->undoStack()->undo();
  EXPECT_EQ(events->tokens(), 1);
}

TEST_F(CanvasWindow, AConnectionBendsAroundANodeInItsWayAndFeedbackPassesBelow) {
  openText(R"(<application name="detour"><modules>
    <module id="a" package="core" type="relay"/>
    <module id="b" package="core" type="relay"/>
    <module id="c" package="core" type="relay"/></modules>
    <connections><connection from="a.out" to="c.in"/><connection from="c.out" to="a.in"/>
    </connections>
    <editor><node ref="a" x="0" y="0"/><node ref="b" x="300" y="-10"/>
    <node ref="c" x="600" y="0"/></editor></application>)");
  lookAt({400, 200});
  ConnectionItem* across = canvas()->connectionItem(0);
  ConnectionItem* back = canvas()->connectionItem(1);
  ASSERT_NE(across, nullptr);
  ASSERT_NE(back, nullptr);
  const QRectF b = canvas()->nodeItem("b")->sceneBody();
  EXPECT_FALSE(crosses(across->path(), b)) << "a -> c runs through b";
  EXPECT_TRUE(
      crosses(connectionCurve(across->path().pointAtPercent(0), across->path().pointAtPercent(1)),
              b));  // the straight curve would
  // The feedback edge keeps passing below both ends.
  EXPECT_GT(back->path().boundingRect().bottom(), canvas()->nodeItem("a")->sceneBody().bottom());
  // While c is dragged, the connections into it follow it.
  const QPointF c = canvas()->nodeItem("c")->scenePos();
  canvas()->selectOnly({"c"});
  drag(c + QPointF(60, 10), c + QPointF(60, 70), [&] {
    EXPECT_NE(canvas()->nodeItem("c")->scenePos(), c);
    EXPECT_EQ(across->path().pointAtPercent(1), canvas()->portScenePos("c", "in"));
  });
  // Moving b out of the way straightens the curve.
  canvas()->selectOnly({"b"});
  drag(b.topLeft() + QPointF(60, 10), b.topLeft() + QPointF(60, 310));
  EXPECT_EQ(across->path(),
            connectionCurve(across->path().pointAtPercent(0), across->path().pointAtPercent(1)));
}

}  // namespace
}  // namespace vrflow::editor::gui
