// The model edits behind the canvas' interactions: insert on a connection, add connected,
// paste at a point, collapse into a composite, a composite's inside.
#include "vrflow/editor/structure_edit.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "vrflow/app/expand.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::editor {
namespace {

const std::string kSource = VRFLOW_TEST_SOURCE_DIR;

app::Catalog coreCatalog() {
  app::Catalog catalog = daemon::makeCatalog();
  const auto status = catalog.addPackageFile(kSource + "/runtime/modules/core/vrflow-package.xml");
  EXPECT_TRUE(status.ok()) << status.error().message;
  return catalog;
}

// points (0,0) and spring (200,0), points.objects -> spring.objects with capacity 4, and
// spring.forces -> points.events.
History pointsAndSpring(const app::Catalog& catalog) {
  History history;
  history.push(*addModule(history.application(), catalog, "core", "points", 0, 0));
  history.push(*addModule(history.application(), catalog, "core", "spring", 200, 0));
  history.push(
      *connect(history.application(), catalog, {"points", "objects"}, {"spring", "objects"}));
  history.push(
      *connect(history.application(), catalog, {"spring", "forces"}, {"points", "events"}));
  app::Application app = history.application();
  app.connections[0].capacity = 4;
  history.push(Edit{"capacity", history.application(), app});
  return history;
}

std::vector<std::string> connections(const app::Application& app) {
  std::vector<std::string> texts;
  for (const auto& c : app.connections)
    texts.push_back(app::toString(c.from) + "->" + app::toString(c.to));
  return texts;
}

TEST(StructureEdit, InsertOnAConnectionSplitsItKeepingItsQueueAndUndoes) {
  const auto catalog = coreCatalog();
  History history = pointsAndSpring(catalog);
  history.push(*addModule(history.application(), catalog, "core", "relay", 100, 200));
  const auto before = history.application();
  auto edit = insertOnConnection(before, catalog, "relay", 0, std::make_pair(100.0, 0.0));
  ASSERT_TRUE(edit.ok()) << edit.error().message;
  history.push(*edit);
  const auto& after = history.application();
  EXPECT_EQ(connections(after),
            (std::vector<std::string>{"points.objects->relay.in", "relay.out->spring.objects",
                                      "spring.forces->points.events"}));
  EXPECT_EQ(after.connections[0].capacity, 4);
  EXPECT_EQ(after.connections[1].capacity, 4);
  EXPECT_EQ(app::findEditorNode(after, "relay")->y, 0);
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(connections(history.application()), connections(before));
  EXPECT_EQ(app::findEditorNode(history.application(), "relay")->y, 200);
}

TEST(StructureEdit, InsertRefusesANodeWhosePortsDoNotFitSayingWhy) {
  const auto catalog = coreCatalog();
  History history = pointsAndSpring(catalog);
  history.push(*addModule(history.application(), catalog, "core", "gravity", 100, 200));
  // gravity takes objects; spring.forces sends events.
  auto refused = insertOnConnection(history.application(), catalog, "gravity", 1);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("no input accepts what 'spring.forces' sends"),
            std::string::npos)
      << refused.error().message;
  auto own = insertOnConnection(history.application(), catalog, "spring", 0);
  ASSERT_FALSE(own.ok());
  EXPECT_NE(own.error().message.find("already an end"), std::string::npos);
}

TEST(StructureEdit, AddingFromASpecConnectsTheFirstCompatiblePortInOneEdit) {
  const auto catalog = coreCatalog();
  History history = pointsAndSpring(catalog);
  const app::Endpoint objects{"points", "objects"};
  const auto specs = compatibleNodeSpecs(history.application(), catalog, &objects, true);
  auto has = [&](const std::string& spec) {
    return std::find(specs.begin(), specs.end(), spec) != specs.end();
  };
  EXPECT_TRUE(has("module core gravity"));
  EXPECT_TRUE(has("module core relay"));
  EXPECT_FALSE(has("module core points"));  // takes events, not objects
  EXPECT_FALSE(has("module core source"));  // no input
  EXPECT_LT(specs.size(), compatibleNodeSpecs(history.application(), catalog).size());

  std::string id;
  auto edit = addNodeFromSpec(history.application(), catalog, "module core gravity", 300, 100,
                              &objects, true, &id);
  ASSERT_TRUE(edit.ok()) << edit.error().message;
  history.push(*edit);
  EXPECT_EQ(id, "gravity");
  EXPECT_EQ(connections(history.application()).back(), "points.objects->gravity.objects");
  ASSERT_TRUE(history.undo());
  EXPECT_EQ(app::findModule(history.application(), "gravity"), nullptr);
  EXPECT_EQ(history.application().connections.size(), 2u);

  // Dragged from an input: the new node's output goes there.
  const app::Endpoint events{"points", "events"};
  auto upstream =
      addNodeFromSpec(history.application(), catalog, "module core spring", 0, 0, &events, false);
  ASSERT_TRUE(upstream.ok()) << upstream.error().message;
  EXPECT_EQ(connections(upstream->after).back(), "spring2.forces->points.events");
  EXPECT_FALSE(
      addNodeFromSpec(history.application(), catalog, "module core source", 0, 0, &objects, true)
          .ok());
}

TEST(StructureEdit, PasteAtPutsTheBoundingBoxCornerAtThePointOrBesideTheOriginal) {
  const auto catalog = coreCatalog();
  History history = pointsAndSpring(catalog);
  const std::string xml = copyAsXml(history.application(), {"points", "spring"});
  auto atPoint = pasteXmlAt(history.application(), xml, std::make_pair(500.0, 300.0));
  ASSERT_TRUE(atPoint.ok());
  EXPECT_EQ(app::findEditorNode(atPoint->after, "points2")->x, 500);
  EXPECT_EQ(app::findEditorNode(atPoint->after, "points2")->y, 300);
  EXPECT_EQ(app::findEditorNode(atPoint->after, "spring2")->x, 700);
  auto beside = pasteXmlAt(history.application(), xml, std::nullopt);
  ASSERT_TRUE(beside.ok());
  // Right of the originals (which end at x = 200 plus a node's width), at the same height.
  EXPECT_EQ(app::findEditorNode(beside->after, "points2")->x, 400);
  EXPECT_EQ(app::findEditorNode(beside->after, "points2")->y, 0);
}

// The flat application with the instance prefix taken off ids, as sorted texts.
std::multiset<std::string> flatTexts(const app::Application& app, const std::string& prefix) {
  auto flat = app::expandComposites(app, app::defaultCompositeSources(app));
  EXPECT_TRUE(flat.ok()) << flat.error().message;
  std::multiset<std::string> texts;
  if (!flat) return texts;
  auto bare = [&](std::string id) {
    return id.rfind(prefix, 0) == 0 ? id.substr(prefix.size()) : id;
  };
  for (const auto& m : flat->modules) {
    std::string text = "module " + bare(m.id) + " " + m.type + " " + m.host;
    for (const auto& p : m.params) text += " " + p.name + "=" + p.value;
    for (const auto& i : m.inputs) text += " " + i.port + ":" + std::to_string(i.initialMessages);
    texts.insert(text);
  }
  for (const auto& c : flat->connections) {
    texts.insert("connection " + bare(c.from.node) + "." + c.from.port + " " + bare(c.to.node) +
                 "." + c.to.port + " " + std::to_string(c.capacity));
  }
  return texts;
}

TEST(StructureEdit, CollapseMakesAValidCompositeThatExpandsToTheSameNetwork) {
  const auto catalog = coreCatalog();
  auto loaded = app::loadApplicationFile(kSource + "/examples/pipeline/pipeline.xml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  History history(*loaded);
  std::string instance;
  auto edit =
      collapseToComposite(history.application(), {"springs", "gravity"}, "forces", &instance);
  ASSERT_TRUE(edit.ok()) << edit.error().message;
  history.push(*edit);
  const auto& app = history.application();
  EXPECT_EQ(instance, "forces");
  ASSERT_EQ(app.composites.size(), 1u);
  const auto& composite = app.composites.front();
  ASSERT_EQ(composite.inputs.size(), 2u);
  EXPECT_EQ(composite.inputs[0].name, "objects");
  EXPECT_EQ(composite.inputs[0].endpoint, "springs.objects");
  EXPECT_EQ(composite.inputs[1].name, "gravity_objects");
  ASSERT_EQ(composite.outputs.size(), 2u);
  EXPECT_EQ(composite.outputs[1].endpoint, "gravity.forces");
  EXPECT_EQ(app::findModule(app, "springs"), nullptr);
  EXPECT_EQ(app::findEditorNode(app, "forces")->x, 240);
  EXPECT_EQ(app::findEditorNode(app, "forces")->y, -80);

  // Saved and loaded again, it validates and expands to the network it was made from.
  auto reloaded = app::loadApplicationString(app::saveApplication(app), loaded->file);
  ASSERT_TRUE(reloaded.ok()) << reloaded.error().message << "\n" << app::saveApplication(app);
  for (const auto& d : app::validate(*reloaded, catalog))
    EXPECT_NE(d.severity, app::Diagnostic::Error) << d.message;
  EXPECT_EQ(flatTexts(*reloaded, "forces:"), flatTexts(*loaded, ""));

  ASSERT_TRUE(history.undo());
  EXPECT_TRUE(history.application().composites.empty());
  EXPECT_EQ(history.application().modules.size(), 5u);
}

TEST(StructureEdit, CollapseRefusesAnEmptySelectionAndUnknownNodes) {
  auto loaded = app::loadApplicationFile(kSource + "/examples/pipeline/pipeline.xml");
  ASSERT_TRUE(loaded.ok());
  EXPECT_FALSE(collapseToComposite(*loaded, {}).ok());
  auto unknown = collapseToComposite(*loaded, {"nobody"});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("nobody"), std::string::npos);
}

TEST(StructureEdit, CompositeInsideHoldsTheInstancesNodesWithTheirInnerIds) {
  auto loaded =
      app::loadApplicationFile(kSource + "/examples/composite_workers/composite_workers.xml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  auto inside = compositeInside(*loaded, "farm");
  ASSERT_TRUE(inside.ok()) << inside.error().message;
  // n = 5 chains and 4 merge filters.
  EXPECT_EQ(inside->filters.size(), 4u);
  EXPECT_NE(app::findFilter(*inside, "merge1"), nullptr);
  EXPECT_TRUE(std::any_of(inside->modules.begin(), inside->modules.end(),
                          [](const app::Module& m) { return m.id.rfind("c0:", 0) == 0; }));
  for (const auto& c : inside->connections) EXPECT_NE(c.from.node.rfind("farm:", 0), 0u);
  EXPECT_FALSE(compositeInside(*loaded, "recorder").ok());
}

}  // namespace
}  // namespace vrflow::editor
