// The canvas' interactions driven like a user would, offscreen: quick-add by typing and from a
// dropped wire, a node dropped on a wire, paste at the cursor, composites opened and collapsed
// (the collapsed network run by the real `vrflow` gives the same digests).
#include <gtest/gtest.h>

#include <QApplication>
#include <QClipboard>
#include <QContextMenuEvent>
#include <QCursor>
#include <QDir>
#include <QFile>
#include <QGraphicsEffect>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLineEdit>
#include <QMenu>
#include <QMimeData>
#include <QProcess>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <QToolButton>
#include <QUndoStack>
#include <memory>

#include "composite_view.hpp"
#include "main_window.hpp"
#include "offscreen_app.hpp"
#include "quick_add.hpp"

namespace vrflow::editor::gui {
namespace {

const QString kSource = VRFLOW_TEST_SOURCE_DIR;

class CanvasInteraction : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_interaction_tests"); }

  void SetUp() override {
    ASSERT_TRUE(dir_.isValid());
    EditorOptions options;
    options.settingsFile = dir_.filePath("settings.ini");
    options.rememberRecent = false;
    window_ = std::make_unique<MainWindow>(options);
    window_->resize(1400, 860);
    window_->show();
    QApplication::processEvents();
  }

  const app::Application& app() const { return window_->application(); }
  Canvas* canvas() const { return window_->canvas(); }
  QPoint view(QPointF scene) const { return canvas()->mapFromScene(scene); }

  void mouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    sendMouse(canvas(), type, pos, button, buttons);
  }

  // Presses the left button at one scene point, moves in steps, releases at another.
  void drag(QPointF fromScene, QPointF toScene, const std::function<void()>& beforeRelease = {}) {
    const QPoint a = view(fromScene);
    const QPoint b = view(toScene);
    mouse(QEvent::MouseButtonPress, a, Qt::LeftButton, Qt::LeftButton);
    for (int step = 1; step <= 4; ++step)
      mouse(QEvent::MouseMove, a + (b - a) * step / 4, Qt::NoButton, Qt::LeftButton);
    if (beforeRelease) beforeRelease();
    mouse(QEvent::MouseButtonRelease, b, Qt::LeftButton, Qt::NoButton);
    QApplication::processEvents();
  }

  void add(const QString& spec, QPointF at) { ASSERT_TRUE(window_->addNode(spec, at)); }

  void dragConnect(const std::string& from, const std::string& to) {
    const auto a = app::parseEndpoint(from);
    const auto b = app::parseEndpoint(to);
    drag(canvas()->portScenePos(a->node, a->port), canvas()->portScenePos(b->node, b->port));
  }

  QPointF centreOf(const std::string& node) const {
    return canvas()->nodeItem(node)->sceneBoundingRect().center();
  }

  // Puts the mouse pointer over the canvas, `at` from its viewport's corner (near it: the
  // offscreen screen is smaller than the window), and gives the scene point under it.
  QPointF pointAt(QPoint at) {
    QCursor::setPos(canvas()->viewport()->mapToGlobal(at));
    QApplication::processEvents();
    EXPECT_EQ(canvas()->viewport()->mapFromGlobal(QCursor::pos()), at);
    return canvas()->mapToScene(at);
  }

  std::vector<std::string> connections() const {
    std::vector<std::string> texts;
    for (const auto& c : app().connections)
      texts.push_back(app::toString(c.from) + "->" + app::toString(c.to));
    return texts;
  }

  // Opens the node's context menu and chooses `action` in it.
  void contextMenuAction(const std::string& node, const QString& action) {
    bool triggered = false;
    QTimer::singleShot(0, [&] {
      auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget());
      ASSERT_NE(menu, nullptr);
      for (QAction* a : menu->actions()) {
        if (a->text() == action) {
          a->trigger();
          triggered = true;
        }
      }
      menu->close();
    });
    const QPoint at = view(centreOf(node));
    QContextMenuEvent event(QContextMenuEvent::Mouse, at, canvas()->viewport()->mapToGlobal(at));
    QApplication::sendEvent(canvas()->viewport(), &event);
    QApplication::processEvents();
    EXPECT_TRUE(triggered) << action.toStdString();
  }

  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(CanvasInteraction, TypingOnTheCanvasOpensQuickAddAndEnterAddsTheTypeAtTheCursor) {
  const QPointF cursor = pointAt({120, 90});
  QTest::keyClicks(canvas(), "s");
  QuickAdd* popup = canvas()->quickAdd();
  ASSERT_NE(popup, nullptr);
  ASSERT_TRUE(popup->isVisible());
  EXPECT_EQ(popup->searchField()->text(), "s");
  QTest::keyClicks(popup->searchField(), "pring");
  // Every type with a word starting "spring" (core's, and the massspring package's when built),
  // core's first.
  ASSERT_FALSE(popup->shownSpecs().isEmpty());
  EXPECT_EQ(popup->shownSpecs().front(), "module core spring");
  for (const QString& spec : popup->shownSpecs())
    EXPECT_TRUE(spec.endsWith(" spring")) << spec.toStdString();
  QTest::keyClick(popup->searchField(), Qt::Key_Return);
  EXPECT_FALSE(popup->isVisible());
  ASSERT_NE(app::findModule(app(), "spring"), nullptr);
  const auto* at = app::findEditorNode(app(), "spring");
  EXPECT_NEAR(at->x, cursor.x(), 10);
  EXPECT_NEAR(at->y, cursor.y(), 10);
  EXPECT_EQ(canvas()->selectedNodes(), std::vector<std::string>{"spring"});

  // Space opens it empty, every type listed; Escape closes it and adds nothing.
  QTest::keyClick(canvas(), Qt::Key_Space);
  ASSERT_TRUE(popup->isVisible());
  EXPECT_TRUE(popup->searchField()->text().isEmpty());
  EXPECT_TRUE(popup->shownSpecs().contains("filter merge"));
  EXPECT_TRUE(popup->shownSpecs().contains("module core points"));
  QTest::keyClick(popup->searchField(), Qt::Key_Escape);
  EXPECT_FALSE(popup->isVisible());
  EXPECT_EQ(app().modules.size(), 1u);

  // Tab opens it too; Down moves to the next shown type.
  QTest::keyClick(canvas(), Qt::Key_Tab);
  ASSERT_TRUE(popup->isVisible());
  QTest::keyClicks(popup->searchField(), "co re");
  ASSERT_EQ(popup->shownSpecs(), (QStringList{"module core recorder", "module core relay"}));
  QTest::keyClick(popup->searchField(), Qt::Key_Down);
  QTest::keyClick(popup->searchField(), Qt::Key_Return);
  EXPECT_NE(app::findModule(app(), "relay"), nullptr);
  EXPECT_EQ(app::findModule(app(), "recorder"), nullptr);
}

TEST_F(CanvasInteraction, ReleasingAWireOverEmptySpaceOffersCompatibleTypesAndConnectsOne) {
  add("module core points", {0, 0});
  drag(canvas()->portScenePos("points", "objects"), {400, 250});
  QuickAdd* popup = canvas()->quickAdd();
  ASSERT_NE(popup, nullptr);
  ASSERT_TRUE(popup->isVisible());
  const QStringList offered = popup->shownSpecs();
  EXPECT_TRUE(offered.contains("module core gravity"));
  EXPECT_TRUE(offered.contains("module core relay"));
  EXPECT_FALSE(offered.contains("module core points"));  // takes events, not objects
  EXPECT_FALSE(offered.contains("module core source"));  // has no input
  QTest::keyClicks(popup->searchField(), "gravity");
  QTest::keyClick(popup->searchField(), Qt::Key_Return);
  ASSERT_NE(app::findModule(app(), "gravity"), nullptr);
  EXPECT_EQ(connections(), std::vector<std::string>{"points.objects->gravity.objects"});
  EXPECT_NEAR(app::findEditorNode(app(), "gravity")->x, 400, 10);
  // One edit: one undo takes the node and its connection away.
  window_->undoStack()->undo();
  EXPECT_EQ(app::findModule(app(), "gravity"), nullptr);
  EXPECT_TRUE(app().connections.empty());
}

TEST_F(CanvasInteraction, DroppingANodeOnAWireInsertsItAsOneUndoableEdit) {
  add("module core points", {0, 0});
  add("module core spring", {400, 0});
  add("module core relay", {200, 300});
  dragConnect("points.objects", "spring.objects");
  ASSERT_EQ(app().connections.size(), 1u);
  const QPointF wire = canvas()->connectionItem(0)->midPoint();
  bool highlighted = false;
  drag(centreOf("relay"), wire, [&] {
    highlighted = canvas()->wireUnderDrop() == std::optional<std::size_t>(0) &&
                  canvas()->connectionItem(0)->graphicsEffect() != nullptr;
  });
  EXPECT_TRUE(highlighted);
  EXPECT_EQ(connections(),
            (std::vector<std::string>{"points.objects->relay.in", "relay.out->spring.objects"}));
  EXPECT_LT(app::findEditorNode(app(), "relay")->y, 200);
  EXPECT_EQ(canvas()->wireUnderDrop(), std::nullopt);
  window_->undoStack()->undo();
  EXPECT_EQ(connections(), std::vector<std::string>{"points.objects->spring.objects"});
  EXPECT_EQ(app::findEditorNode(app(), "relay")->y, 300);
}

TEST_F(CanvasInteraction, DroppingAnIncompatibleNodeOnAWireIsRefusedWithTheReason) {
  add("module core points", {0, 0});
  add("module core spring", {400, 0});
  add("module core gravity", {200, 300});
  dragConnect("spring.forces", "points.events");
  ASSERT_EQ(app().connections.size(), 1u);
  bool refusedWhileHovering = false;
  drag(centreOf("gravity"), canvas()->connectionItem(0)->midPoint(), [&] {
    refusedWhileHovering = canvas()->connectionItem(0)->graphicsEffect() != nullptr &&
                           !canvas()->wireUnderDrop().has_value();
  });
  EXPECT_TRUE(refusedWhileHovering);
  EXPECT_EQ(connections(), std::vector<std::string>{"spring.forces->points.events"});
  EXPECT_TRUE(canvas()->lastRefusal().contains("no input accepts what 'spring.forces' sends"))
      << canvas()->lastRefusal().toStdString();
}

TEST_F(CanvasInteraction, DroppingAPaletteEntryOnAWireInsertsTheNewNode) {
  add("module core points", {0, 0});
  add("module core spring", {400, 0});
  dragConnect("points.objects", "spring.objects");
  QMimeData mime;
  mime.setData(kNodeMime, "module core relay");
  const QPoint at = view(canvas()->connectionItem(0)->midPoint());
  QWidget* viewport = canvas()->viewport();
  QDragEnterEvent enter(at, Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(viewport, &enter);
  QDragMoveEvent move(at, Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(viewport, &move);
  EXPECT_EQ(canvas()->wireUnderDrop(), std::optional<std::size_t>(0));
  // Leaving the canvas puts the wire out; coming back lights it again.
  QDragLeaveEvent leave;
  QApplication::sendEvent(viewport, &leave);
  EXPECT_EQ(canvas()->wireUnderDrop(), std::nullopt);
  EXPECT_EQ(canvas()->connectionItem(0)->graphicsEffect(), nullptr);
  QApplication::sendEvent(viewport, &enter);
  QApplication::sendEvent(viewport, &move);
  ASSERT_EQ(canvas()->wireUnderDrop(), std::optional<std::size_t>(0));
  QDropEvent dropped(QPointF(at), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(viewport, &dropped);
  QApplication::processEvents();
  EXPECT_EQ(connections(),
            (std::vector<std::string>{"points.objects->relay.in", "relay.out->spring.objects"}));
  window_->undoStack()->undo();
  EXPECT_EQ(app::findModule(app(), "relay"), nullptr);
  EXPECT_EQ(app().connections.size(), 1u);
}

TEST_F(CanvasInteraction, PasteAndDuplicateLandAtTheCursorOrBesideTheOriginal) {
  add("module core points", {0, 0});
  add("module core spring", {300, 0});
  dragConnect("points.objects", "spring.objects");
  canvas()->selectOnly({"points", "spring"});
  window_->copySelection();
  const QPointF cursor = pointAt({150, 120});
  window_->paste();
  ASSERT_NE(app::findEditorNode(app(), "points2"), nullptr);
  EXPECT_NEAR(app::findEditorNode(app(), "points2")->x, cursor.x(), 10);
  EXPECT_NEAR(app::findEditorNode(app(), "points2")->y, cursor.y(), 10);
  EXPECT_NEAR(app::findEditorNode(app(), "spring2")->x, cursor.x() + 300, 10);

  // The cursor away from the canvas: beside the original, at its height.
  QCursor::setPos(window_->mapToGlobal(QPoint(5, 5)));  // on the menu bar
  canvas()->selectOnly({"points"});
  window_->duplicateSelection();
  ASSERT_NE(app::findEditorNode(app(), "points3"), nullptr);
  EXPECT_GT(app::findEditorNode(app(), "points3")->x, 100);
  EXPECT_EQ(app::findEditorNode(app(), "points3")->y, 0);
}

TEST_F(CanvasInteraction, DoubleClickingACompositeInstanceOpensItsInsideAndBackReturns) {
  ASSERT_TRUE(window_->openFile(kSource + "/examples/composite_workers/composite_workers.xml"));
  QApplication::processEvents();
  const QPoint at = view(centreOf("farm"));
  mouse(QEvent::MouseButtonPress, at, Qt::LeftButton, Qt::LeftButton);
  mouse(QEvent::MouseButtonRelease, at, Qt::LeftButton, Qt::NoButton);
  mouse(QEvent::MouseButtonDblClick, at, Qt::LeftButton, Qt::LeftButton);
  mouse(QEvent::MouseButtonRelease, at, Qt::LeftButton, Qt::NoButton);
  QApplication::processEvents();
  CompositeView* inside = canvas()->compositeView();
  ASSERT_NE(inside, nullptr) << canvas()->lastRefusal().toStdString();
  EXPECT_TRUE(inside->isVisible());
  EXPECT_EQ(inside->geometry(), canvas()->rect());
  EXPECT_TRUE(inside->breadcrumb().contains("farm (composite workers)"))
      << inside->breadcrumb().toStdString();
  EXPECT_TRUE(inside->breadcrumb().contains("outputs: objects"));
  for (const char* node : {"merge1", "merge4", "c0:points", "c4:gravity"}) {
    EXPECT_NE(inside->canvas()->nodeItem(node), nullptr) << node;
  }
  EXPECT_EQ(inside->canvas()->nodeItem("recorder"), nullptr);
  EXPECT_FALSE(inside->canvas()->isInteractive());  // read-only
  const QString shot =
      qEnvironmentVariable("VRFLOW_TEST_SCREENSHOT_DIR", dir_.path()) + "/composite_drill_down.png";
  EXPECT_TRUE(window_->grab().save(shot));

  // Back returns to the application, unchanged.
  QTest::mouseClick(inside->backButton(), Qt::LeftButton);
  QApplication::processEvents();
  EXPECT_EQ(canvas()->compositeView(), nullptr);
  EXPECT_FALSE(window_->modified());
  EXPECT_EQ(window_->undoStack()->count(), 0);

  // A plain module does not open.
  EXPECT_FALSE(canvas()->openComposite("recorder"));
}

// Per output port of a `vrflow run --report` (module ids without `prefix`): its last digest
// and message count.
std::map<QString, std::pair<QString, int>> runDigests(const QString& file, const QString& folder,
                                                      const QString& prefix) {
  QProcess run;
  run.setWorkingDirectory(folder);
  run.setProcessChannelMode(QProcess::MergedChannels);
  const QString report = file + ".report.json";
  run.start(QCoreApplication::applicationDirPath() + "/vrflow",
            {"run", file, "--iterations", "30", "--report", report});
  EXPECT_TRUE(run.waitForFinished(60000));
  EXPECT_EQ(run.exitCode(), 0) << run.readAll().toStdString();
  QFile in(report);
  EXPECT_TRUE(in.open(QIODevice::ReadOnly)) << report.toStdString();
  std::map<QString, std::pair<QString, int>> digests;
  for (const QJsonValue& value : QJsonDocument::fromJson(in.readAll())["outputs"].toArray()) {
    const QJsonObject output = value.toObject();
    QString module = output["module"].toString();
    if (module.startsWith(prefix)) module = module.mid(prefix.size());
    digests[module + "." + output["port"].toString()] = {output["last_digest"].toString(),
                                                         output["messages"].toInt()};
  }
  return digests;
}

TEST_F(CanvasInteraction, CollapsingASelectionMakesAValidCompositeThatRunsWithTheSameDigests) {
  const QString original = dir_.filePath("pipeline.xml");
  ASSERT_TRUE(QFile::copy(kSource + "/examples/pipeline/pipeline.xml", original));
  ASSERT_TRUE(window_->openFile(original));
  canvas()->selectOnly({"springs", "gravity"});
  contextMenuAction("springs", "Collapse into composite");
  ASSERT_EQ(app().composites.size(), 1u) << canvas()->lastRefusal().toStdString();
  ASSERT_EQ(app().instances.size(), 1u);
  EXPECT_EQ(app().instances[0].id, "group");
  EXPECT_EQ(app().modules.size(), 3u);
  EXPECT_EQ(canvas()->selectedNodes(), std::vector<std::string>{"group"});
  ASSERT_NE(canvas()->nodeItem("group"), nullptr);
  const QString collapsed = dir_.filePath("collapsed.xml");
  ASSERT_TRUE(window_->saveAs(collapsed));

  QProcess validate;
  validate.setProcessChannelMode(QProcess::MergedChannels);
  validate.start(QCoreApplication::applicationDirPath() + "/vrflow", {"validate", collapsed});
  ASSERT_TRUE(validate.waitForFinished(30000));
  EXPECT_EQ(validate.exitCode(), 0) << validate.readAll().toStdString();

  const auto before = runDigests(original, dir_.path(), "");
  const auto after = runDigests(collapsed, dir_.path(), "group:");
  // Every output sends as many messages, and what leaves the composite gives the same bits
  // downstream: the points' and the relay's digests are equal. (The forces' own digests carry
  // their sender's slot, which moves: instances expand after the file's own modules.)
  ASSERT_EQ(before.size(), 4u);
  ASSERT_EQ(after.size(), 4u);
  for (const auto& [port, digest] : before) {
    ASSERT_EQ(after.count(port), 1u) << port.toStdString();
    EXPECT_EQ(after.at(port).second, digest.second) << port.toStdString();
  }
  EXPECT_EQ(after.at("chain.objects"), before.at("chain.objects"));
  EXPECT_EQ(after.at("relay.out"), before.at("relay.out"));

  // The new instance opens like any composite; one undo brings the nodes back.
  ASSERT_TRUE(canvas()->openComposite("group"));
  EXPECT_NE(canvas()->compositeView()->canvas()->nodeItem("springs"), nullptr);
  QTest::keyClick(canvas()->compositeView()->canvas(), Qt::Key_Escape);
  EXPECT_EQ(canvas()->compositeView(), nullptr);
  window_->undoStack()->undo();
  EXPECT_TRUE(app().composites.empty());
  EXPECT_EQ(app().modules.size(), 5u);
}

}  // namespace
}  // namespace vrflow::editor::gui
