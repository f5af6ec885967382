// The editor's document driven like a user would, offscreen: comments kept through edits, the
// properties panel updated in place, the undo actions on New/Open, the palette's counts, the
// hostfile dialog and a misspelt parameter fixed from the problems list.
#include <gtest/gtest.h>

#include <QAbstractItemView>
#include <QAction>
#include <QApplication>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFileDialog>
#include <QLineEdit>
#include <QListView>
#include <QListWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QToolButton>
#include <QUndoStack>
#include <filesystem>
#include <memory>
#include <regex>

#include "main_window.hpp"
#include "offscreen_app.hpp"

namespace vrflow::editor::gui {
namespace {

namespace fs = std::filesystem;

// Dialogs answered without a person: errors and warnings are recorded, files come from a field.
class ScriptedReporter : public Reporter {
 public:
  void error(QWidget*, const QString& title, const QString& text) override {
    messages << title + ": " + text;
  }
  void warning(QWidget*, const QString& title, const QString& text) override {
    messages << title + ": " + text;
  }
  Choice askToSave(QWidget*, const QString&) override { return Choice::Discard; }
  QString fileName(QWidget*, bool, const QString&) override { return nextFile; }
  QStringList messages;
  QString nextFile;
};

// Every `<!--...-->` of an XML text, in order.
std::vector<std::string> commentsIn(const std::string& xml) {
  static const std::regex comment("<!--([\\s\\S]*?)-->");
  std::vector<std::string> found;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), comment);
       it != std::sregex_iterator(); ++it) {
    found.push_back((*it)[1].str());
  }
  return found;
}

std::string readFile(const QString& path) {
  QFile file(path);
  EXPECT_TRUE(file.open(QIODevice::ReadOnly)) << path.toStdString();
  return file.readAll().toStdString();
}

QString example(const char* path) {
  return QString(VRFLOW_TEST_SOURCE_DIR) + "/" + path;
}

class EditorDocument : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { startOffscreenApplication("vrflow_editor_document_tests"); }

  void SetUp() override {
    ASSERT_TRUE(dir_.isValid());
    EditorOptions options;
    options.settingsFile = dir_.filePath("settings.ini");
    options.reporter = &reporter_;
    options.rememberRecent = false;
    window_ = std::make_unique<MainWindow>(options);
    window_->resize(1400, 860);
    window_->show();
    window_->activateWindow();
    ASSERT_TRUE(QTest::qWaitForWindowActive(window_.get()));
  }

  const app::Application& app() const { return window_->application(); }
  PropertiesPanel* properties() const { return window_->properties(); }

  // Types `text` into a parameter's field as a user does: select all, type, then `finish`.
  void typeInto(QWidget* field, const QString& text, Qt::Key finish) {
    ASSERT_NE(field, nullptr);
    field->setFocus(Qt::TabFocusReason);
    QApplication::processEvents();
    if (auto* box = qobject_cast<QAbstractSpinBox*>(field)) box->selectAll();
    if (auto* edit = qobject_cast<QLineEdit*>(field)) edit->selectAll();
    QTest::keyClicks(QApplication::focusWidget(), text);
    QTest::keyClick(QApplication::focusWidget(), finish);
    QApplication::processEvents();
  }

  static bool holdsFocus(const QWidget* widget) {
    const QWidget* focus = QApplication::focusWidget();
    return focus != nullptr && (focus == widget || widget->isAncestorOf(focus));
  }

  QAction* undoAction() const {
    for (QAction* action : window_->findChildren<QAction*>()) {
      if (action->shortcut() == QKeySequence(QKeySequence::Undo)) return action;
    }
    return nullptr;
  }

  QTemporaryDir dir_;
  ScriptedReporter reporter_;
  std::unique_ptr<MainWindow> window_;
};

TEST_F(EditorDocument, EditingAParameterOfThePaperSceneKeepsEveryComment) {
  const QString path = example("examples/paper_scene/paper_scene.xml");
  const std::string original = readFile(path);
  const std::vector<std::string> comments = commentsIn(original);
  ASSERT_GE(comments.size(), 4u);
  ASSERT_TRUE(window_->openFile(path));
  window_->canvas()->selectOnly({"net"});
  ASSERT_EQ(properties()->node(), "net");
  typeInto(properties()->parameterWidget("mass"), "9", Qt::Key_Return);
  ASSERT_EQ(app::paramString(app::findModule(app(), "net")->params, "mass", ""), "9");
  ASSERT_TRUE(window_->modified());
  const QString saved = dir_.filePath("paper_scene.xml");
  ASSERT_TRUE(window_->saveAs(saved));
  const std::string text = readFile(saved);
  EXPECT_NE(text.find("<param name=\"mass\" value=\"9\"/>"), std::string::npos);
  EXPECT_EQ(commentsIn(text), comments);
  // The comment about smooth interactions still comes just before net-collisions.
  const std::size_t smooth = text.find("Net collisions are a smooth interaction");
  ASSERT_NE(smooth, std::string::npos);
  EXPECT_EQ(text.find("<module id=", smooth), text.find("<module id=\"net-collisions\""));
  EXPECT_TRUE(reporter_.messages.isEmpty()) << reporter_.messages.join("\n").toStdString();
}

TEST_F(EditorDocument, TabMovesAcrossParameterFieldsApplyingEachEdit) {
  ASSERT_TRUE(window_->addNode("module core spring", QPointF(0, 0)));
  window_->canvas()->selectOnly({"spring"});
  QWidget* stiffness = properties()->parameterWidget("stiffness");
  QWidget* damping = properties()->parameterWidget("damping");
  QWidget* rest = properties()->parameterWidget("rest");
  ASSERT_NE(stiffness, nullptr);
  ASSERT_NE(damping, nullptr);
  ASSERT_NE(rest, nullptr);
  typeInto(stiffness, "123.5", Qt::Key_Tab);
  EXPECT_EQ(app::paramString(app::findModule(app(), "spring")->params, "stiffness", ""), "123.5");
  // The same widgets, the focus on the next field.
  EXPECT_EQ(properties()->parameterWidget("stiffness"), stiffness);
  EXPECT_TRUE(holdsFocus(damping));
  QTest::keyClick(QApplication::focusWidget(), Qt::Key_A, Qt::ControlModifier);
  QTest::keyClicks(QApplication::focusWidget(), "0.75");
  QTest::keyClick(QApplication::focusWidget(), Qt::Key_Tab);
  QApplication::processEvents();
  EXPECT_EQ(app::paramString(app::findModule(app(), "spring")->params, "damping", ""), "0.75");
  EXPECT_TRUE(holdsFocus(rest));
  QTest::keyClick(QApplication::focusWidget(), Qt::Key_A, Qt::ControlModifier);
  QTest::keyClicks(QApplication::focusWidget(), "2");
  QTest::keyClick(QApplication::focusWidget(), Qt::Key_Tab);
  QApplication::processEvents();
  EXPECT_EQ(app::paramString(app::findModule(app(), "spring")->params, "rest", ""), "2");
  EXPECT_EQ(properties()->parameterWidget("rest"), rest);
  EXPECT_EQ(window_->undoStack()->count(), 4);  // the node, then three values
  // Undo shows the previous value in the same widget.
  window_->undoStack()->undo();
  EXPECT_EQ(properties()->parameterWidget("rest"), rest);
  EXPECT_EQ(qobject_cast<QDoubleSpinBox*>(rest)->value(), 1);  // the default again
  // Another node: the panel is built for it.
  ASSERT_TRUE(window_->addNode("module core points", QPointF(300, 0)));
  window_->canvas()->selectOnly({"points"});
  EXPECT_EQ(properties()->parameterWidget("stiffness"), nullptr);
  EXPECT_NE(properties()->parameterWidget("count"), nullptr);
}

TEST_F(EditorDocument, TheThreeFieldsOfAVec3FitTheDockAtItsDefaultWidth) {
  ASSERT_TRUE(window_->addNode("module core gravity", QPointF(0, 0)));
  window_->canvas()->selectOnly({"gravity"});
  QApplication::processEvents();
  QWidget* g = properties()->parameterWidget("g");
  ASSERT_NE(g, nullptr);
  for (int i = 0; i < 3; ++i) {
    auto* box = g->findChild<QDoubleSpinBox*>(QString("component%1").arg(i));
    ASSERT_NE(box, nullptr);
    EXPECT_TRUE(box->isVisible());
    // The whole number can be read, and the field lies inside the panel.
    const int needed = box->fontMetrics().horizontalAdvance(box->text());
    EXPECT_GE(box->width(), needed) << box->text().toStdString();
    const QRect inPanel(box->mapTo(properties(), QPoint(0, 0)), box->size());
    EXPECT_TRUE(properties()->rect().contains(inPanel)) << i;
  }
}

TEST_F(EditorDocument, OverrideForThisRunOffersTheParameterAndItsValue) {
  ASSERT_TRUE(window_->addNode("module core spring", QPointF(0, 0)));
  window_->canvas()->selectOnly({"spring"});
  std::vector<std::string> offered;
  QObject::connect(properties(), &PropertiesPanel::overrideForRunRequested,
                   [&](const std::string& node, const std::string& name, const std::string& value) {
                     offered = {node, name, value};
                   });
  auto* button = properties()->findChild<QToolButton*>("override:stiffness");
  ASSERT_NE(button, nullptr);
  QTest::mouseClick(button, Qt::LeftButton);
  EXPECT_EQ(offered, (std::vector<std::string>{"spring", "stiffness", "50"}));
  EXPECT_EQ(window_->undoStack()->count(), 1);  // only the node: the file keeps its value
}

TEST_F(EditorDocument, NewAndOpenLeaveTheUndoActionsEmpty) {
  QAction* undo = undoAction();
  ASSERT_NE(undo, nullptr);
  ASSERT_TRUE(window_->addNode("module core spring", QPointF(0, 0)));
  EXPECT_TRUE(undo->isEnabled());
  EXPECT_NE(undo->text(), "&Undo");
  ASSERT_TRUE(window_->openFile(example("examples/paper_scene/paper_scene.xml")));
  EXPECT_FALSE(undo->isEnabled());
  EXPECT_EQ(undo->text(), "&Undo");
  ASSERT_TRUE(window_->addNode("module core points", QPointF(0, 600)));
  EXPECT_TRUE(undo->isEnabled());
  window_->newFile();
  EXPECT_FALSE(undo->isEnabled());
  EXPECT_EQ(undo->text(), "&Undo");
}

TEST_F(EditorDocument, PaletteGroupCountsFollowTheSearch) {
  Palette* palette = window_->palette();
  auto* search = palette->findChild<QLineEdit*>();
  ASSERT_NE(search, nullptr);
  auto visibleCounts = [palette] {
    int groupsShown = 0;
    for (int g = 0; g < palette->tree()->topLevelItemCount(); ++g) {
      QTreeWidgetItem* group = palette->tree()->topLevelItem(g);
      if (group->isHidden()) continue;
      ++groupsShown;
      int shown = 0;
      for (int i = 0; i < group->childCount(); ++i) shown += group->child(i)->isHidden() ? 0 : 1;
      const QString text = group->text(0);
      const bool all = shown == group->childCount();
      EXPECT_TRUE(all ? text.endsWith(QString("(%1)").arg(shown))
                      : text.endsWith(QString("(%1 of %2)").arg(shown).arg(group->childCount())))
          << text.toStdString();
    }
    return groupsShown;
  };
  EXPECT_GE(visibleCounts(), 2);
  search->setFocus();
  QTest::keyClicks(search, "spring");
  QApplication::processEvents();
  EXPECT_GE(visibleCounts(), 1);
  QTreeWidgetItem* spring = palette->findEntry("module core spring");
  ASSERT_NE(spring, nullptr);
  EXPECT_TRUE(spring->parent()->text(0).contains(" of "))
      << spring->parent()->text(0).toStdString();
  search->clear();
  EXPECT_FALSE(spring->parent()->text(0).contains(" of "));
}

TEST_F(EditorDocument, TheHostfileDialogShowsHostfilesWhateverTheirNames) {
  QTemporaryDir folder;
  ASSERT_TRUE(folder.isValid());
  const QStringList names = {"hosts", "cluster.hostfile", "hostfile-big", "nodes.txt", "app.xml"};
  for (const QString& name : names) {
    QFile file(folder.filePath(name));
    ASSERT_TRUE(file.open(QIODevice::WriteOnly));
    file.write("node1 slots=2\n");
  }
  const std::unique_ptr<QFileDialog> dialog = makeHostfileDialog(window_.get(), folder.path());
  dialog->setOption(QFileDialog::DontUseNativeDialog);
  dialog->show();
  auto* view = dialog->findChild<QListView*>("listView");
  ASSERT_NE(view, nullptr);
  auto listed = [view] {
    QStringList shown;
    const QModelIndex root = view->rootIndex();
    for (int row = 0; row < view->model()->rowCount(root); ++row) {
      const QModelIndex index = view->model()->index(row, 0, root);
      // A name filter may grey a file out instead of hiding it: count what can be chosen.
      if (index.flags().testFlag(Qt::ItemIsEnabled)) shown << index.data().toString();
    }
    shown.sort();
    return shown;
  };
  QStringList all = names;
  all.sort();
  QTRY_COMPARE(listed(), all);
  dialog->selectNameFilter(dialog->nameFilters().at(1));  // "Hostfiles (...)"
  QStringList hostfiles = {"cluster.hostfile", "hostfile-big", "hosts", "nodes.txt"};
  QTRY_COMPARE(listed(), hostfiles);
  dialog->reject();
}

TEST_F(EditorDocument, ActivatingADidYouMeanProblemRenamesTheParameter) {
  ASSERT_TRUE(window_->addNode("module core spring", QPointF(0, 0)));
  ASSERT_TRUE(window_->apply(setParameter(app(), "spring", "stifness", "3")));
  QListWidget* problems = window_->problemList();
  QListWidgetItem* found = nullptr;
  for (int row = 0; row < problems->count(); ++row) {
    if (problems->item(row)->text().contains("rename it to 'stiffness'"))
      found = problems->item(row);
  }
  ASSERT_NE(found, nullptr);
  problems->scrollToItem(found);
  // Click the problem, then Enter: the list's activation, as a double-click gives.
  const QRect rect = problems->visualItemRect(found);
  QTest::mouseClick(problems->viewport(), Qt::LeftButton, Qt::NoModifier,
                    QPoint(rect.left() + 20, rect.center().y()));
  ASSERT_EQ(problems->currentItem(), found);
  QTest::keyClick(problems, Qt::Key_Return);
  QApplication::processEvents();
  const auto& params = app::findModule(app(), "spring")->params;
  EXPECT_EQ(app::findParam(params, "stifness"), nullptr);
  EXPECT_EQ(app::paramString(params, "stiffness", ""), "3");
  for (int row = 0; row < problems->count(); ++row) {
    EXPECT_FALSE(problems->item(row)->text().contains("stifness"));
  }
  // One edit: undo brings the misspelt name back.
  window_->undoStack()->undo();
  EXPECT_EQ(app::paramString(app::findModule(app(), "spring")->params, "stifness", ""), "3");
}

}  // namespace
}  // namespace vrflow::editor::gui
