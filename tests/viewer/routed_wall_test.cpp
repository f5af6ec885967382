// examples/routed_wall end to end: the demo scene on a 2 x 2 wall of viewers fed through one
// route filter, against the same wall fed directly.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../runtime/process_helpers.hpp"

namespace vrflow::viewer {
namespace {

namespace fs = std::filesystem;
using vrflow::testing::TempDir;

constexpr int kIterations = 30;

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

// An application of the example's folder (routed_wall.xml, or direct_wall.xml: the same without
// routing), made small for a test: tiles of 96 x 54 without supersampling, PNG frames into
// `frames`, the scene file named by its absolute path (the copy lives in a temporary folder).
std::string smallApplication(const std::string& name, const std::string& frames) {
  std::string app =
      vrflow::testing::readFile(vrflow::testing::sourceDir() + "/examples/routed_wall/" + name);
  replaceAll(app, "\"../paper_scene/scene.json\"",
             "\"" + vrflow::testing::sourceDir() + "/examples/paper_scene/scene.json\"");
  replaceAll(app, "<param name=\"width\" value=\"480\"/>", "<param name=\"width\" value=\"96\"/>");
  replaceAll(app, "<param name=\"height\" value=\"270\"/>",
             "<param name=\"height\" value=\"54\"/>");
  for (const char* dir : {"routed-wall", "direct-wall", "routed-fluid-wall", "direct-fluid-wall"}) {
    replaceAll(app, "<param name=\"output-dir\" value=\"" + std::string(dir) + "\"/>",
               "<param name=\"output-dir\" value=\"" + frames +
                   "\"/><param name=\"format\" value=\"png\"/><param name=\"supersample\" "
                   "value=\"1\"/>");
  }
  return app;
}

// The <modules> section of an application.
std::string modulesOf(const std::string& app) {
  const auto begin = app.find("<modules>");
  const auto end = app.find("</modules>");
  return begin == std::string::npos || end == std::string::npos ? std::string()
                                                                : app.substr(begin, end - begin);
}

struct WallRun {
  nlohmann::json report;
  std::string bodiesState, netState;
};

// Runs `app` (or the file `existing`, whose relative paths resolve beside it) in dir/name.
WallRun runIn(const TempDir& dir, const std::string& name, const std::string& app,
              const std::string& existing = "", int iterations = kIterations) {
  const auto folder = dir.file(name);
  fs::create_directories(folder);
  const auto file = existing.empty() ? dir.write(name + ".xml", app) : existing;
  const auto result = vrflow::testing::runCommand(
      {"/bin/sh", "-c",
       "cd '" + folder + "' && exec '" + vrflow::testing::binDir() + "/vrflow' run '" + file +
           "' -n " + std::to_string(iterations) + " --no-progress --report report.json"},
      120);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  WallRun run;
  run.report = nlohmann::json::parse(vrflow::testing::readFile(folder + "/report.json"));
  run.bodiesState = vrflow::testing::readFile(folder + "/bodies-final.json");
  run.netState = vrflow::testing::readFile(folder + "/net-final.txt");
  return run;
}

// Bytes delivered to each tile's objects input, by tile id.
std::map<std::string, double> bytesToTiles(const nlohmann::json& report) {
  std::map<std::string, double> bytes;
  for (const auto& c : report["connections"]) {
    const auto to = c["to"].get<std::string>();
    if (to.rfind("tile", 0) == 0 && to.ends_with(".objects")) {
      bytes[to.substr(0, to.find('.'))] += c["bytes"].get<double>();
    }
  }
  return bytes;
}

// The digest of every output port of the simulation (not the viewers': the tiles, the demo's
// camera).
std::map<std::string, std::string> simulationDigests(const nlohmann::json& report) {
  std::map<std::string, std::string> digests;
  for (const auto& output : report["outputs"]) {
    const auto module = output["module"].get<std::string>();
    if (module.rfind("tile", 0) == 0 || module == "camera") continue;
    digests[module + "." + output["port"].get<std::string>()] = output["last_digest"].dump();
  }
  return digests;
}

std::size_t framesOf(const std::string& folder, const std::string& prefix) {
  std::size_t frames = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const auto name = entry.path().filename().string();
    if (name.rfind(prefix + "_", 0) == 0 && name.ends_with(".png")) ++frames;
  }
  return frames;
}

TEST(RoutedWall, EachTileGetsFewerBytesAndDrawsTheSameFramesAndTheSimulationIsUnchanged) {
  TempDir dir;
  const std::string routed = smallApplication("routed_wall.xml", dir.file("routed/frames"));
  const std::string directApp = smallApplication("direct_wall.xml", dir.file("direct/frames"));
  // The two files differ only by routing: the same modules with the same parameters.
  const std::string modules = modulesOf(smallApplication("routed_wall.xml", "FRAMES"));
  ASSERT_FALSE(modules.empty());
  ASSERT_EQ(modules, modulesOf(smallApplication("direct_wall.xml", "FRAMES")));
  ASSERT_EQ(directApp.find("type=\"route\""), std::string::npos);
  const WallRun withRoute = runIn(dir, "routed", routed);
  const WallRun direct = runIn(dir, "direct", directApp);
  ASSERT_EQ(withRoute.report["status"], "ok");
  ASSERT_EQ(direct.report["status"], "ok");

  // Every tile drew every iteration, routed or not, and shows the same picture: a routed tile
  // holds the current state of every object its volume meets and draws only those; the others
  // are outside its view (shadows are off in the example).
  int identical = 0;
  for (int k = 0; k < 4; ++k) {
    const std::string tile = "tile" + std::to_string(k);
    EXPECT_EQ(framesOf(dir.file("routed/frames"), tile), std::size_t{kIterations}) << tile;
    EXPECT_EQ(framesOf(dir.file("direct/frames"), tile), std::size_t{kIterations}) << tile;
    for (int i = 0; i < kIterations; ++i) {
      char name[64];
      std::snprintf(name, sizeof name, "/frames/%s_%06d.png", tile.c_str(), i);
      const auto routedFrame = vrflow::testing::readFile(dir.file("routed") + name);
      EXPECT_FALSE(routedFrame.empty()) << name;
      if (!routedFrame.empty() &&
          routedFrame == vrflow::testing::readFile(dir.file("direct") + name)) {
        ++identical;
      }
    }
  }
  EXPECT_EQ(identical, 4 * kIterations) << "frames differ between routed and direct tiles";

  // Each tile receives fewer bytes through the route than straight from the animators.
  const auto routedBytes = bytesToTiles(withRoute.report);
  const auto directBytes = bytesToTiles(direct.report);
  ASSERT_EQ(routedBytes.size(), 4u);
  ASSERT_EQ(directBytes.size(), 4u);
  double routedTotal = 0, directTotal = 0;
  for (const auto& [tile, bytes] : routedBytes) {
    EXPECT_LT(bytes, directBytes.at(tile)) << tile;
    routedTotal += bytes;
    directTotal += directBytes.at(tile);
    std::printf("%s: %.0f bytes/iteration routed, %.0f direct\n", tile.c_str(), bytes / kIterations,
                directBytes.at(tile) / kIterations);
  }
  std::printf("4 tiles: %.0f bytes/iteration routed, %.0f direct (%.2fx less)\n",
              routedTotal / kIterations, directTotal / kIterations, directTotal / routedTotal);
  // The tiles pace the scene, so these bytes are the same in every run: over 30 iterations
  // (the first goes whole to every tile) the 4 tiles get 2.58x less (README: over 300).
  EXPECT_GT(directTotal, 2.4 * routedTotal);

  // Routing never changes what the simulation computes.
  const auto digests = simulationDigests(withRoute.report);
  EXPECT_EQ(digests.size(), 6u);  // bodies.objects, net.objects and the 4 interactors' forces
  EXPECT_TRUE(digests.contains("bodies.objects") && digests.contains("net.objects"));
  EXPECT_EQ(digests, simulationDigests(direct.report));
  EXPECT_EQ(withRoute.bodiesState, direct.bodiesState);
  EXPECT_EQ(withRoute.netState, direct.netState);
  // ... nor does the wall and its pacing: the demo scene itself (one viewer, not paced) computes
  // the same bits.
  const WallRun demo = runIn(
      dir, "demo", "", vrflow::testing::sourceDir() + "/examples/paper_scene/paper_scene.xml");
  EXPECT_EQ(digests, simulationDigests(demo.report));
  EXPECT_EQ(withRoute.bodiesState, demo.bodiesState);
  EXPECT_EQ(withRoute.netState, demo.netState);
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
}

// The demo scene with its fluid seen from above (routed_fluid_wall.xml, direct_fluid_wall.xml):
// the liquid's particles are most of the bytes, and as 4 x 1 x 4 regions whose seams fall on
// the tiles' (x = 1.25, z = 0), each tile receives about a quarter of them.
TEST(RoutedWall, WithTheFluidEachTileGetsAtLeast3xFewerBytesTheSameFramesAndTheSameSimulation) {
  constexpr int kFluidIterations = 20;
  TempDir dir;
  const std::string routed = smallApplication("routed_fluid_wall.xml", dir.file("routed/frames"));
  const std::string directApp =
      smallApplication("direct_fluid_wall.xml", dir.file("direct/frames"));
  ASSERT_EQ(modulesOf(smallApplication("routed_fluid_wall.xml", "FRAMES")),
            modulesOf(smallApplication("direct_fluid_wall.xml", "FRAMES")));
  const WallRun withRoute = runIn(dir, "routed", routed, "", kFluidIterations);
  const WallRun direct = runIn(dir, "direct", directApp, "", kFluidIterations);
  ASSERT_EQ(withRoute.report["status"], "ok");
  ASSERT_EQ(direct.report["status"], "ok");
  const auto routedBytes = bytesToTiles(withRoute.report);
  const auto directBytes = bytesToTiles(direct.report);
  ASSERT_EQ(routedBytes.size(), 4u);
  ASSERT_EQ(directBytes.size(), 4u);
  for (const auto& [tile, bytes] : routedBytes) {
    std::printf("%s: %.0f bytes/iteration routed, %.0f direct (%.2fx less)\n", tile.c_str(),
                bytes / kFluidIterations, directBytes.at(tile) / kFluidIterations,
                directBytes.at(tile) / bytes);
    EXPECT_GT(directBytes.at(tile), 3.0 * bytes) << tile;
  }
  // The same pictures: a particle region a tile is not sent lies outside its view.
  int identical = 0;
  for (int k = 0; k < 4; ++k) {
    const std::string tile = "tile" + std::to_string(k);
    EXPECT_EQ(framesOf(dir.file("routed/frames"), tile), std::size_t{kFluidIterations}) << tile;
    for (int i = 0; i < kFluidIterations; ++i) {
      char name[64];
      std::snprintf(name, sizeof name, "/frames/%s_%06d.png", tile.c_str(), i);
      const auto routedFrame = vrflow::testing::readFile(dir.file("routed") + name);
      if (!routedFrame.empty() &&
          routedFrame == vrflow::testing::readFile(dir.file("direct") + name)) {
        ++identical;
      }
    }
  }
  EXPECT_EQ(identical, 4 * kFluidIterations) << "frames differ between routed and direct tiles";
  const auto digests = simulationDigests(withRoute.report);
  EXPECT_TRUE(digests.contains("water.fluid") && digests.contains("water.forces"));
  EXPECT_EQ(digests, simulationDigests(direct.report));
  EXPECT_EQ(withRoute.bodiesState, direct.bodiesState);
  EXPECT_EQ(withRoute.netState, direct.netState);
  // ... and the same as the demo scene's own (paper_scene_fluid.xml: one viewer, no pacing, its
  // particles as one object): the regions change how the particles travel, not the physics.
  const WallRun demo = runIn(
      dir, "demo", "", vrflow::testing::sourceDir() + "/examples/paper_scene/paper_scene_fluid.xml",
      kFluidIterations);
  EXPECT_EQ(withRoute.bodiesState, demo.bodiesState);
  EXPECT_EQ(withRoute.netState, demo.netState);
  EXPECT_EQ(digests.at("water.forces"), simulationDigests(demo.report).at("water.forces"));
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::viewer
