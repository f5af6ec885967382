// The editor's model layer, without Qt.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/editor/analysis.hpp"
#include "vrflow/editor/edit.hpp"

namespace vrflow::editor {
namespace {

namespace fs = std::filesystem;

app::Catalog coreCatalog() {
  app::Catalog catalog = daemon::makeCatalog();
  const auto status = catalog.addPackageFile(std::string(VRFLOW_TEST_SOURCE_DIR) +
                                             "/runtime/modules/core/vrflow-package.xml");
  EXPECT_TRUE(status.ok()) << status.error().message;
  return catalog;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// points -> spring -> points: a cycle, and a recorder.
app::Application chain(History& history, const app::Catalog& catalog) {
  std::string points, spring;
  history.push(*addModule(history.application(), catalog, "core", "points", 0, 0, &points));
  history.push(*addModule(history.application(), catalog, "core", "spring", 200, 0, &spring));
  history.push(*connect(history.application(), catalog, {points, "objects"}, {spring, "objects"}));
  history.push(*connect(history.application(), catalog, {spring, "forces"}, {points, "events"}));
  return history.application();
}

TEST(EditorModel, AddModuleGivesFreshIdsHostAndPositionAndUndoes) {
  const auto catalog = coreCatalog();
  History history;
  std::string first, second;
  history.push(*addModule(history.application(), catalog, "core", "relay", 10, 20, &first));
  history.push(*addModule(history.application(), catalog, "core", "relay", 30, 40, &second));
  EXPECT_EQ(first, "relay");
  EXPECT_EQ(second, "relay2");
  ASSERT_EQ(history.application().modules.size(), 2u);
  EXPECT_EQ(history.application().modules[0].host, "localhost");
  const auto* pos = app::findEditorNode(history.application(), "relay2");
  ASSERT_NE(pos, nullptr);
  EXPECT_EQ(pos->x, 30);
  EXPECT_TRUE(history.modified());
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(history.application().modules.size(), 1u);
  EXPECT_EQ(app::findEditorNode(history.application(), "relay2"), nullptr);
  ASSERT_TRUE(history.redo());
  EXPECT_EQ(history.application().modules.size(), 2u);
  EXPECT_FALSE(addModule(history.application(), catalog, "core", "nosuch", 0, 0).ok());
}

TEST(EditorModel, ConnectsCompatiblePortsAndUndoes) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  ASSERT_EQ(history.application().connections.size(), 2u);
  EXPECT_EQ(app::toString(history.application().connections[1].from), "spring.forces");
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(history.application().connections.size(), 1u);
  ASSERT_TRUE(history.redo());
  EXPECT_EQ(history.application().connections.size(), 2u);
}

TEST(EditorModel, RefusesIncompatibleConnectionsSayingWhy) {
  const auto catalog = coreCatalog();
  History history;
  const auto app = chain(history, catalog);
  // objects into an events input
  auto why = connectionRefusal(app, catalog, {"points", "objects"}, {"points", "events"});
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("port data types differ"), std::string::npos) << *why;
  EXPECT_NE(why->find("'objects'"), std::string::npos) << *why;
  // input to input, output to output
  EXPECT_TRUE(
      connectionRefusal(app, catalog, {"spring", "objects"}, {"points", "events"}).has_value());
  EXPECT_TRUE(
      connectionRefusal(app, catalog, {"spring", "forces"}, {"points", "objects"}).has_value());
  // twice the same
  why = connectionRefusal(app, catalog, {"points", "objects"}, {"spring", "objects"});
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("already connected"), std::string::npos);
  // stamps-only endIt into a full input
  why = connectionRefusal(app, catalog, {"points", "endIt"}, {"spring", "objects"});
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("stamps-only"), std::string::npos) << *why;
  // and the edit itself refuses
  EXPECT_FALSE(connect(app, catalog, {"points", "objects"}, {"points", "events"}).ok());
  EXPECT_FALSE(
      connectionRefusal(app, catalog, {"points", "endIt"}, {"spring", "beginIt"}).has_value());
}

TEST(EditorModel, EditsParametersAndInitialMessages) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  history.push(*setParameter(history.application(), "spring", "stiffness", "123"));
  EXPECT_EQ(
      app::paramString(app::findModule(history.application(), "spring")->params, "stiffness", ""),
      "123");
  history.push(*setInitialMessages(history.application(), "points", "events", 1));
  EXPECT_EQ(app::inputConfigOrDefault(*app::findModule(history.application(), "points"), "events")
                .initialMessages,
            1);
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(app::findInputConfig(*app::findModule(history.application(), "points"), "events"),
            nullptr);
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(app::findParam(app::findModule(history.application(), "spring")->params, "stiffness"),
            nullptr);
  EXPECT_FALSE(setParameter(history.application(), "nobody", "x", "1").ok());
}

TEST(EditorModel, HostsAddRenameAssignRemoveAndImport) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  history.push(*addHost(history.application(), "node1", "10.0.0.1"));
  history.push(*assignHost(history.application(), {"spring"}, "node1"));
  EXPECT_EQ(app::findModule(history.application(), "spring")->host, "node1");
  history.push(*renameHost(history.application(), "node1", "gpu"));
  EXPECT_EQ(app::findModule(history.application(), "spring")->host, "gpu");
  EXPECT_FALSE(assignHost(history.application(), {"spring"}, "nowhere").ok());
  history.push(*removeHost(history.application(), "gpu"));
  EXPECT_EQ(app::findModule(history.application(), "spring")->host, "localhost");
  EXPECT_FALSE(removeHost(history.application(), "localhost").ok());  // the last one
  history.push(
      *importHostfile(history.application(), "# cluster\nwall1 192.168.0.11\nwall2 slots=4\n\n"));
  ASSERT_EQ(history.application().hosts.size(), 3u);
  EXPECT_EQ(history.application().hosts[1].address, "192.168.0.11");
  EXPECT_EQ(history.application().hosts[2].id, "wall2");
  EXPECT_EQ(history.application().hosts[2].address, "wall2");
  // The saved file says where each module runs.
  history.push(*assignHost(history.application(), {"points", "spring"}, "wall1"));
  const std::string xml = app::saveApplication(history.application());
  EXPECT_NE(xml.find("host=\"wall1\""), std::string::npos);
}

TEST(EditorModel, RemovingNodesRemovesTheirConnectionsAndPositions) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  history.push(*removeNodes(history.application(), {"spring"}));
  EXPECT_TRUE(history.application().connections.empty());
  EXPECT_EQ(app::findEditorNode(history.application(), "spring"), nullptr);
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(history.application().connections.size(), 2u);
}

TEST(EditorModel, CopyPasteRenamesAndKeepsInnerConnections) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  const std::string xml = copyAsXml(history.application(), {"points", "spring"});
  std::vector<std::string> ids;
  history.push(*pasteXml(history.application(), xml, 50, 50, &ids));
  EXPECT_EQ(ids, (std::vector<std::string>{"points2", "spring2"}));
  ASSERT_EQ(history.application().connections.size(), 4u);
  EXPECT_EQ(app::toString(history.application().connections[2].from), "points2.objects");
  EXPECT_EQ(app::findEditorNode(history.application(), "spring2")->x, 250);
  EXPECT_FALSE(pasteXml(history.application(), "not xml", 0, 0).ok());
}

TEST(EditorModel, RenameFollowsConnections) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  history.push(*renameNode(history.application(), "spring", "springs"));
  EXPECT_EQ(history.application().connections[0].to.node, "springs");
  EXPECT_FALSE(renameNode(history.application(), "springs", "points").ok());
  EXPECT_FALSE(renameNode(history.application(), "springs", "a.b").ok());
}

TEST(EditorModel, SavedEditsReloadEqual) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  history.push(*setParameter(history.application(), "spring", "damping", "0.25"));
  history.push(*setInitialMessages(history.application(), "points", "events", 2));
  history.push(*addHost(history.application(), "far", "10.1.1.1"));
  history.push(*assignHost(history.application(), {"spring"}, "far"));
  const std::string xml = app::saveApplication(history.application());
  auto reloaded = app::loadApplicationString(xml, "x.xml");
  ASSERT_TRUE(reloaded.ok()) << reloaded.error().message;
  EXPECT_EQ(app::saveApplication(*reloaded), xml);
  EXPECT_EQ(app::findModule(*reloaded, "spring")->host, "far");
}

TEST(EditorModel, EveryExampleSavedUnchangedGivesTheSameBytes) {
  const auto catalog = coreCatalog();
  int count = 0;
  int canonical = 0;
  for (const auto& entry :
       fs::recursive_directory_iterator(fs::path(VRFLOW_TEST_SOURCE_DIR) / "examples")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".xml" || name.ends_with(".vrc.xml") ||
        name == "vrflow-package.xml")
      continue;
    const std::string text = readFile(entry.path());
    auto app = app::loadApplicationString(text, entry.path().string());
    ASSERT_TRUE(app.ok()) << entry.path() << ": " << app.error().message;
    const OpenedText opened{text, app::saveApplication(*app)};
    EXPECT_EQ(textToSave(*app, opened), text) << entry.path();
    if (opened.canonical == text) ++canonical;
    // An edit undone gives the file's bytes back too; a real edit gives the writer's text.
    History history(*app);
    if (!app->modules.empty()) {
      history.push(*setParameter(history.application(), app->modules[0].id, "editor-test", "1"));
      EXPECT_EQ(textToSave(history.application(), opened),
                app::saveApplication(history.application()));
      ASSERT_TRUE(history.undo());
      EXPECT_EQ(textToSave(history.application(), opened), text);
    }
    ++count;
  }
  EXPECT_GE(count, 5);
  EXPECT_GE(canonical, 1);  // some examples are in the writer's form: their bytes come from it
}

TEST(EditorModel, DeadlockCycleIsAProblemOnItsConnections) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  auto problems = findProblems(history.application(), catalog);
  const auto cycle = std::find_if(problems.begin(), problems.end(),
                                  [](const Problem& p) { return !p.cycle.empty(); });
  ASSERT_NE(cycle, problems.end());
  EXPECT_EQ(cycle->severity, app::Diagnostic::Error);
  EXPECT_EQ(cycle->cycle, (std::vector<std::size_t>{0, 1}));
  EXPECT_NE(cycle->text.find("would deadlock"), std::string::npos);
  history.push(*setInitialMessages(history.application(), "points", "events", 1));
  problems = findProblems(history.application(), catalog);
  EXPECT_TRUE(problems.empty()) << problems.front().text;
}

TEST(EditorModel, ProblemsPointAtTheirNodeOrConnection) {
  const auto catalog = coreCatalog();
  History history;
  chain(history, catalog);
  history.push(*setInitialMessages(history.application(), "points", "events", 1));
  history.push(*setParameter(history.application(), "spring", "stiffness", "-4"));
  history.push(*addModule(history.application(), catalog, "core", "recorder", 0, 0));
  auto problems = findProblems(history.application(), catalog);
  ASSERT_EQ(problems.size(), 2u);
  for (const auto& p : problems) {
    if (p.text.find("stiffness") != std::string::npos) {
      EXPECT_EQ(p.node, "spring");
    } else {
      EXPECT_EQ(p.node, "recorder") << p.text;  // required input 'in' unconnected
    }
  }
  // A connection at fault (made in code, bypassing the editor's refusal) points at itself.
  app::Application bad = history.application();
  bad.connections.push_back({{"points", "objects"}, {"points", "events"}, 0, {}, {}});
  problems = findProblems(bad, catalog);
  const auto it = std::find_if(problems.begin(), problems.end(),
                               [](const Problem& p) { return p.connection.has_value(); });
  ASSERT_NE(it, problems.end());
  EXPECT_EQ(*it->connection, 2u);
}

TEST(EditorModel, ProblemsOfAnUnchangedFileCarryItsOwnLines) {
  const auto catalog = coreCatalog();
  // Blank lines (which the canonical writer leaves out, keeping the comment) shift every line
  // of the file against the canonical text.
  const std::string text =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"x\" version=\"1\">\n"
      "  <!-- one -->\n\n\n  <modules>\n"
      "    <module id=\"r\" package=\"core\" type=\"recorder\"/>\n  </modules>\n</application>\n";
  auto app = app::loadApplicationString(text, "x.xml");
  ASSERT_TRUE(app.ok());
  const OpenedText opened{text, app::saveApplication(*app)};
  auto problems = findProblems(*app, catalog, {}, &opened);
  ASSERT_EQ(problems.size(), 1u);  // required input 'in' unconnected
  EXPECT_EQ(problems[0].node, "r");
  EXPECT_EQ(problems[0].text.rfind("x.xml:7:", 0), 0u) << problems[0].text;
  // Once edited, the canonical text is checked (the module is on line 5 there).
  History history(*app);
  history.push(*setParameter(history.application(), "r", "file", "a.csv"));
  problems = findProblems(history.application(), catalog, {}, &opened);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].node, "r");
  EXPECT_EQ(problems[0].text.rfind("x.xml:5:", 0), 0u) << problems[0].text;
}

TEST(EditorModel, AutoLayoutGoesLeftToRight) {
  const auto catalog = coreCatalog();
  History history;
  std::string a, b, c;
  history.push(*addModule(history.application(), catalog, "core", "source", 0, 0, &a));
  history.push(*addModule(history.application(), catalog, "core", "relay", 0, 0, &b));
  history.push(*addModule(history.application(), catalog, "core", "recorder", 0, 0, &c));
  history.push(*connect(history.application(), catalog, {a, "out"}, {b, "in"}));
  history.push(*connect(history.application(), catalog, {b, "out"}, {c, "in"}));
  const auto positions = autoLayout(history.application());
  ASSERT_EQ(positions.size(), 3u);
  EXPECT_LT(positions.at(a).first + 160, positions.at(b).first + 1);
  EXPECT_LT(positions.at(b).first + 160, positions.at(c).first + 1);
}

TEST(EditorModel, ParsesRunReportsAndFindsTheFailingModule) {
  const auto report = parseRunReport(
      R"({"status":"failed","error":"module 'springs' (host local, pid 12) exited with status 3",
    "modules":[{"id":"springs","iterations":7,"exit":"status 3"}],
    "connections":[{"from":"a.out","to":"b.in","messages":5,"bytes":640,"dropped":0}],
    "timing":{"wall_s":2.5}})");
  ASSERT_TRUE(report.ok());
  EXPECT_EQ(report->failedModule, "springs");
  EXPECT_EQ(report->modules.at("springs").iterations, 7);
  ASSERT_EQ(report->connections.size(), 1u);
  EXPECT_EQ(report->connections[0].bytes, 640);
  EXPECT_DOUBLE_EQ(report->wallSeconds, 2.5);
  EXPECT_FALSE(parseRunReport("{oops").ok());
}

}  // namespace
}  // namespace vrflow::editor
