// What an edit changed (the canvas applies it), instance badges and the edits of notes and
// frames, without Qt.
#include "vrflow/editor/changes.hpp"

#include <gtest/gtest.h>

#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/editor/edit.hpp"
#include "vrflow/editor/notes.hpp"

namespace vrflow::editor {
namespace {

app::Catalog catalogWithCore() {
  app::Catalog catalog = daemon::makeCatalog();
  const auto status = catalog.addPackageFile(std::string(VRFLOW_TEST_SOURCE_DIR) +
                                             "/runtime/modules/core/vrflow-package.xml");
  EXPECT_TRUE(status.ok()) << status.error().message;
  return catalog;
}

// points at (0, 0) -> spring at (300, 0).
app::Application pointsToSpring(const app::Catalog& catalog) {
  app::Application app;
  app.hosts.push_back({"a", "127.0.0.1", {}});
  app = addModule(app, catalog, "core", "points", 0, 0)->after;
  app = addModule(app, catalog, "core", "spring", 300, 0)->after;
  app = connect(app, catalog, {"points", "objects"}, {"spring", "objects"})->after;
  return app;
}

TEST(EditChanges, AParameterEditChangesOnlyThatNode) {
  const auto catalog = catalogWithCore();
  const auto app = pointsToSpring(catalog);
  const auto edit = setParameter(app, "spring", "stiffness", "12");
  ASSERT_TRUE(edit) << edit.error().message;
  const Changes changes = diff(edit->before, edit->after);
  EXPECT_EQ(changes.nodesChanged, std::vector<std::string>{"spring"});
  EXPECT_TRUE(changes.nodesAdded.empty());
  EXPECT_TRUE(changes.nodesRemoved.empty());
  EXPECT_TRUE(changes.nodesMoved.empty());
  EXPECT_TRUE(changes.connectionsAdded.empty());
  EXPECT_FALSE(changes.hostsChanged);
  EXPECT_FALSE(changes.empty());
  EXPECT_TRUE(diff(app, app).empty());
}

TEST(EditChanges, AddsRemovalsMovesConnectionsAndHostsAreTold) {
  const auto catalog = catalogWithCore();
  const auto app = pointsToSpring(catalog);
  auto removed = removeNodes(app, {"points"});
  ASSERT_TRUE(removed);
  Changes changes = diff(removed->before, removed->after);
  EXPECT_EQ(changes.nodesRemoved, std::vector<std::string>{"points"});
  EXPECT_EQ(changes.connectionsRemoved,
            std::vector<std::string>{"points.objects -> spring.objects"});
  changes = diff(removed->after, removed->before);  // undone
  EXPECT_EQ(changes.nodesAdded, std::vector<std::string>{"points"});
  EXPECT_EQ(changes.connectionsAdded, std::vector<std::string>{"points.objects -> spring.objects"});

  auto moved = moveNodes(app, {{"spring", {500, 40}}});
  ASSERT_TRUE(moved);
  changes = diff(moved->before, moved->after);
  EXPECT_EQ(changes.nodesMoved, std::vector<std::string>{"spring"});
  EXPECT_TRUE(changes.nodesChanged.empty());

  auto host = addHost(app, "b", "10.0.0.2");
  ASSERT_TRUE(host);
  EXPECT_TRUE(diff(host->before, host->after).hostsChanged);
  auto note = addNote(app, 0, 0, "why");
  ASSERT_TRUE(note);
  changes = diff(note->before, note->after);
  EXPECT_TRUE(changes.notesChanged);
  EXPECT_FALSE(changes.framesChanged);
}

TEST(EditChanges, InstanceBadgesComeFromTheExpandedComposite) {
  InstanceSummary summary;
  summary.modules = 5;
  summary.hosts = {"a", "b"};
  EXPECT_EQ(badgeText(summary), "5 modules on a, b");
  summary.hosts = {"a", "b", "c"};
  EXPECT_EQ(badgeText(summary), "5 modules on 3 hosts");
  EXPECT_TRUE(instanceSummaries(app::Application{}).empty());
}

TEST(NotesAndFrames, AreAddedEditedAndRemovedAsEdits) {
  app::Application app;
  std::string note, note2, frame;
  app = addNote(app, 10, 20, "first", &note)->after;
  app = addNote(app, 10, 200, "second", &note2)->after;
  app = addFrame(app, {0, 0, 300, 150}, "Group", &frame)->after;
  EXPECT_EQ(note, "note");
  EXPECT_EQ(note2, "note2");
  EXPECT_EQ(frame, "frame");
  app = setNoteText(app, note, "line 1\nline 2")->after;
  EXPECT_EQ(findNote(app, note)->text, "line 1\nline 2");
  EXPECT_FALSE(setNoteText(app, note, "line 1\nline 2"));  // unchanged
  app = setNoteArea(app, note, {15, 25, 10, 300})->after;
  EXPECT_EQ(findNote(app, note)->width, 40);  // the smallest note
  EXPECT_EQ(findNote(app, note)->height, 300);
  app = setFrameTitle(app, frame, "Physics")->after;
  app = setFrameColor(app, frame, "#4caf50")->after;
  EXPECT_EQ(findFrame(app, frame)->title, "Physics");
  EXPECT_EQ(findFrame(app, frame)->color, "#4caf50");
  EXPECT_FALSE(setFrameTitle(app, "nowhere", "x"));
  const auto removed = removeNotesAndFrames(app, {note, frame});
  ASSERT_TRUE(removed);
  EXPECT_EQ(removed->after.notes.size(), 1u);
  EXPECT_TRUE(removed->after.frames.empty());
  EXPECT_FALSE(removeNotesAndFrames(removed->after, {note}));
}

TEST(NotesAndFrames, MovingAFrameCarriesTheNodesAndNotesInsideOnly) {
  const auto catalog = catalogWithCore();
  app::Application app = pointsToSpring(catalog);  // points at 0, spring at 300
  std::string frame;
  app = addFrame(app, {-20, -40, 250, 200}, "Group", &frame)->after;
  app = addNote(app, 10, 100, "inside")->after;
  app = addNote(app, 600, 100, "outside")->after;
  const auto moved = moveFrame(app, frame, 100, 50);
  ASSERT_TRUE(moved);
  const app::Application& after = moved->after;
  EXPECT_EQ(app::findEditorNode(after, "points")->x, 100);
  EXPECT_EQ(app::findEditorNode(after, "points")->y, 50);
  EXPECT_EQ(app::findEditorNode(after, "spring")->x, 300);  // outside: stays
  EXPECT_EQ(after.notes[0].x, 110);
  EXPECT_EQ(after.notes[1].x, 600);
  EXPECT_EQ(findFrame(after, frame)->x, 80);
  EXPECT_EQ(findFrame(after, frame)->width, 250);
  // A resize moves nothing.
  const auto resized = setFrameArea(app, frame, {-20, -40, 900, 400});
  ASSERT_TRUE(resized);
  EXPECT_EQ(app::findEditorNode(resized->after, "points")->x, 0);
  EXPECT_EQ(diff(resized->before, resized->after).nodesMoved.size(), 0u);
}

}  // namespace
}  // namespace vrflow::editor
