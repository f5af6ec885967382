// The editor shows a display wall: a node that uses a wall file (the display_wall instance of
// examples/display_wall, a viewer module with `wall`) opens, by a double click or its context
// menu, as the wall: its tiles where they hang, with their hosts and displays.
#include "wall_view.hpp"

#include <gtest/gtest.h>

#include <QApplication>
#include <QContextMenuEvent>
#include <QGraphicsRectItem>
#include <QGraphicsView>
#include <QMenu>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <QToolButton>
#include <QUndoStack>
#include <fstream>
#include <memory>

#include "main_window.hpp"
#include "offscreen_app.hpp"

namespace vrflow::editor::gui {
namespace {

const QString kSource = VRFLOW_TEST_SOURCE_DIR;

class WallViewTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_wall_tests"); }

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

  Canvas* canvas() const { return window_->canvas(); }

  QPoint centreOf(const std::string& node) const {
    return canvas()->mapFromScene(canvas()->nodeItem(node)->sceneBoundingRect().center());
  }

  void mouse(QEvent::Type type, QPoint pos, Qt::MouseButton button, Qt::MouseButtons buttons) {
    sendMouse(canvas(), type, pos, button, buttons);
  }

  void doubleClick(const std::string& node) {
    const QPoint at = centreOf(node);
    mouse(QEvent::MouseButtonPress, at, Qt::LeftButton, Qt::LeftButton);
    mouse(QEvent::MouseButtonRelease, at, Qt::LeftButton, Qt::NoButton);
    mouse(QEvent::MouseButtonDblClick, at, Qt::LeftButton, Qt::LeftButton);
    mouse(QEvent::MouseButtonRelease, at, Qt::LeftButton, Qt::NoButton);
    QApplication::processEvents();
  }

  // The actions of the node's context menu, and `choose` triggered among them.
  QStringList contextMenu(const std::string& node, const QString& choose = {}) {
    QStringList texts;
    QTimer::singleShot(0, [&] {
      auto* menu = qobject_cast<QMenu*>(QApplication::activePopupWidget());
      ASSERT_NE(menu, nullptr);
      for (QAction* a : menu->actions()) {
        texts << a->text();
        if (a->text() == choose) a->trigger();
      }
      menu->close();
    });
    const QPoint at = centreOf(node);
    QContextMenuEvent event(QContextMenuEvent::Mouse, at, canvas()->viewport()->mapToGlobal(at));
    QApplication::sendEvent(canvas()->viewport(), &event);
    QApplication::processEvents();
    return texts;
  }

  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(WallViewTest, DoubleClickingTheDisplayWallInstanceShowsItsSixteenTilesWhereTheyHang) {
  ASSERT_TRUE(window_->openFile(kSource + "/examples/display_wall/display_wall_4x4.xml"));
  QApplication::processEvents();
  doubleClick("wall");
  WallView* wall = canvas()->wallView();
  ASSERT_NE(wall, nullptr) << canvas()->lastRefusal().toStdString();
  EXPECT_TRUE(wall->isVisible());
  EXPECT_EQ(wall->geometry(), canvas()->rect());
  EXPECT_EQ(canvas()->compositeView(), nullptr);
  EXPECT_TRUE(
      wall->breadcrumb().contains("wall (wall wall_4x4.wall: 4 \u00D7 4 tiles of 0.8 m "
                                  "\u00D7 0.45 m, mullions 1.5 cm)"))
      << wall->breadcrumb().toStdString();
  // Tile (c, r) at c * (0.8 + 0.015) m from the left, r * (0.45 + 0.015) m from the top, in
  // millimetres; its host from the wall file, with its address from the application.
  for (int t = 0; t < 16; ++t) {
    const std::string id = "t" + std::to_string(t);
    const QGraphicsRectItem* item = wall->tileItem(id);
    ASSERT_NE(item, nullptr) << id;
    const int col = t % 4, row = t / 4;
    EXPECT_NEAR(item->rect().left(), col * 815.0, 1e-6) << id;
    EXPECT_NEAR(item->rect().top(), row * 465.0, 1e-6) << id;
    EXPECT_NEAR(item->rect().width(), 800.0, 1e-6) << id;
    EXPECT_NEAR(item->rect().height(), 450.0, 1e-6) << id;
    const QString text = wall->tileText(id);
    EXPECT_TRUE(text.contains(QString("host h%1 (127.0.53.%2)").arg(row).arg(row + 1)))
        << text.toStdString();
    EXPECT_TRUE(text.contains(QString("display :0.%1").arg(col))) << text.toStdString();
    EXPECT_TRUE(text.contains("240 \u00D7 135 px")) << text.toStdString();
  }
  // Tiles on one host share its colour; the rows' hosts differ.
  EXPECT_EQ(wall->tileItem("t0")->pen().color(), wall->tileItem("t3")->pen().color());
  EXPECT_NE(wall->tileItem("t0")->pen().color(), wall->tileItem("t4")->pen().color());
  const QString shot =
      qEnvironmentVariable("VRFLOW_TEST_SCREENSHOT_DIR", dir_.path()) + "/display_wall_4x4.png";
  EXPECT_TRUE(window_->grab().save(shot));

  // Escape returns to the application, unchanged.
  QTest::keyClick(wall->view(), Qt::Key_Escape);
  QApplication::processEvents();
  EXPECT_EQ(canvas()->wallView(), nullptr);
  EXPECT_FALSE(window_->modified());
  EXPECT_EQ(window_->undoStack()->count(), 0);

  // The context menu offers the wall and, still, the composite's inside.
  const QStringList actions = contextMenu("wall", "Show wall");
  EXPECT_TRUE(actions.contains("Show wall"));
  EXPECT_TRUE(actions.contains("Open composite"));
  ASSERT_NE(canvas()->wallView(), nullptr);
  QTest::mouseClick(canvas()->wallView()->backButton(), Qt::LeftButton);
  QApplication::processEvents();
  EXPECT_EQ(canvas()->wallView(), nullptr);
}

TEST_F(WallViewTest, AViewerModuleWithAWallFileOpensAsItsOneTileWall) {
  ASSERT_TRUE(window_->openFile(kSource + "/examples/display_wall/one_view.xml"));
  QApplication::processEvents();
  doubleClick("view");
  WallView* wall = canvas()->wallView();
  ASSERT_NE(wall, nullptr) << canvas()->lastRefusal().toStdString();
  ASSERT_NE(wall->tileItem("view"), nullptr);
  EXPECT_EQ(wall->wall().tiles.size(), 1u);
  // A module without a wall does not open one; nor does its context menu offer it.
  EXPECT_FALSE(canvas()->openWall("water"));
  EXPECT_TRUE(canvas()->lastRefusal().contains("'water' names no wall file"));
  EXPECT_FALSE(contextMenu("bodies").contains("Show wall"));
}

TEST_F(WallViewTest, AWallFileThatCannotBeReadIsRefusedNamingItsLine) {
  const QString app = dir_.filePath("bad.xml");
  {
    std::ofstream out(dir_.filePath("bad.wall").toStdString());
    out << "grid 2 1\ntile a 0 0 h0 :0 0 0\ntile a 1 0 h0 :0 0 0\n";
    std::ofstream xml(app.toStdString());
    xml << "<?xml version=\"1.0\"?>\n<application name=\"bad\" version=\"1\">\n"
           "  <modules>\n    <module id=\"v\" package=\"viewer\" type=\"viewer\">\n"
           "      <param name=\"wall\" value=\"bad.wall\"/>\n"
           "      <param name=\"wall-tile\" value=\"a\"/>\n    </module>\n  </modules>\n"
           "</application>\n";
  }
  ASSERT_TRUE(window_->openFile(app));
  QApplication::processEvents();
  doubleClick("v");
  EXPECT_EQ(canvas()->wallView(), nullptr);
  EXPECT_TRUE(canvas()->lastRefusal().contains("bad.wall:3: tile 'a' declared twice"))
      << canvas()->lastRefusal().toStdString();
  std::remove(dir_.filePath("bad.wall").toStdString().c_str());
  EXPECT_FALSE(canvas()->openWall("v"));
  EXPECT_TRUE(canvas()->lastRefusal().contains("bad.wall"))
      << canvas()->lastRefusal().toStdString();
}

}  // namespace
}  // namespace vrflow::editor::gui
