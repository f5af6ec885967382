// examples/display_wall end to end: the paper scene with its fluid's surface on a swap-locked
// 2 x 2 wall (the example's composite), recorded by vrflow-wall-mosaic, against one viewer of the
// whole wall in the same run; the 4 x 4 wall over four loopback hosts, its filters per host.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../runtime/process_helpers.hpp"
#include "vrflow/viewer/image.hpp"
#include "wall_scene.hpp"

namespace vrflow::viewer {
namespace {

namespace fs = std::filesystem;
using vrflow::testing::TempDir;

constexpr int kIterations = 12;

void replaceAll(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

std::string exampleDir() {
  return vrflow::testing::sourceDir() + "/examples/display_wall";
}

// An example application made small for CI: the scene file by its full path, the wall file of
// `wall`, and the liquid on a grid of half the resolution (16 x 32 x 16 cells of 0.125 m: the
// same pool, 8 times fewer particles; still 4 x 1 x 4 surface regions).
std::string smallExample(const std::string& file, const std::string& wallName,
                         const std::string& wall) {
  std::string app = vrflow::testing::readFile(exampleDir() + "/" + file);
  replaceAll(app, "\"../paper_scene/scene.json\"",
             "\"" + vrflow::testing::sourceDir() + "/examples/paper_scene/scene.json\"");
  replaceAll(app, "value=\"" + wallName + "\"", "value=\"" + wall + "\"");
  replaceAll(app, "name=\"nx\" value=\"32\"", "name=\"nx\" value=\"16\"");
  replaceAll(app, "name=\"ny\" value=\"64\"", "name=\"ny\" value=\"32\"");
  replaceAll(app, "name=\"nz\" value=\"32\"", "name=\"nz\" value=\"16\"");
  replaceAll(app, "name=\"cell-size\" value=\"0.0625\"", "name=\"cell-size\" value=\"0.125\"");
  return app;
}

// The example with a wall file of `dir` (the example's geometry at 160 x 90 pixels per tile and
// without mullions, so that the mosaic can equal one view), plus a viewer `whole` drawing a
// one-tile wall of the same size and place, fed by the same scene.
std::string application(const TempDir& dir) {
  std::string wall = vrflow::testing::readFile(exampleDir() + "/wall_2x2.wall");
  replaceAll(wall, "pixels 480 270", "pixels 160 90");
  replaceAll(wall, "bezel 0.03 0.03", "bezel 0 0");
  dir.write("wall.wall", wall);
  dir.write("whole.wall",
            "grid 1 1\npixels 320 180\nsize 3.2 1.8\ncentre 0 1.3 3.5\n"
            "right 1 0 0\nup 0 1 0\neye 0 2.4 7.5\ntile whole 0 0 h0 :0 0 0\n");
  std::string app = smallExample("display_wall.xml", "wall_2x2.wall", dir.file("wall.wall"));
  replaceAll(app, "  </modules>",
             "    <module id=\"whole\" package=\"viewer\" type=\"viewer\" host=\"h0\">"
             "<param name=\"wall\" value=\"" +
                 dir.file("whole.wall") +
                 "\"/><param name=\"wall-tile\" value=\"whole\"/><param name=\"supersample\" "
                 "value=\"1\"/><param name=\"format\" value=\"png\"/><param name=\"output-dir\" "
                 "value=\"display-wall\"/><param name=\"prefix\" value=\"whole\"/>"
                 "</module>\n  </modules>");
  replaceAll(app, "    <connection from=\"scene.out\" to=\"wall.objects\"/>",
             "    <connection from=\"scene.out\" to=\"wall.objects\"/>\n"
             "    <connection from=\"scene.out\" to=\"whole.objects\"/>\n"
             "    <connection from=\"water.fluid\" to=\"whole.objects\"/>");
  return app;
}

// The tiles draw the liquid's surface routed to them, the whole view all of it.
TEST(DisplayWall, TheRecordedMosaicOfTheSwapLockedWallEqualsOneViewOfTheWholeWall) {
  TempDir dir;
  const auto file = dir.write("display_wall.xml", application(dir));
  const auto result =
      vrflow::testing::runCommand({"/bin/sh", "-c",
                                   "cd '" + dir.path() + "' && exec '" + vrflow::testing::binDir() +
                                       "/vrflow' run '" + file + "' --composites '" + exampleDir() +
                                       "' -n " + std::to_string(kIterations) + " --no-progress"},
                                  180);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto mosaic = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-wall-mosaic", dir.file("wall.wall"),
       dir.file("display-wall"), "--out", dir.file("mosaic")},
      60);
  ASSERT_EQ(mosaic.exitCode, 0) << mosaic.err;
  int worst = 0;
  for (int k = 0; k < kIterations; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "_%06d.png", k);
    const auto joined = readPng(dir.file("mosaic/wall") + name);
    const auto whole = readPng(dir.file("display-wall/whole") + name);
    ASSERT_TRUE(joined.ok() && whole.ok()) << "frame " << k;
    ASSERT_EQ(joined->width, 320);
    ASSERT_EQ(joined->height, 180);
    int differing = 0, inside = 0;
    for (int y = 0; y < 180; ++y) {
      for (int x = 0; x < 320; ++x) {
        if (joined->at(x, y) == whole->at(x, y)) continue;
        ++differing;
        if (!testing::onAnEdge(*whole, x, y)) ++inside;
      }
    }
    EXPECT_EQ(inside, 0) << "frame " << k << ": " << differing << " pixels differ";
    EXPECT_LE(differing, 320 * 180 / 1000) << "frame " << k;
    worst = std::max(worst, differing);
  }
  RecordProperty("worst_differing_pixels", worst);
  // Every tile showed frames 0 .. kIterations - 2, in order (the last is drawn, never released).
  for (int t = 0; t < 4; ++t) {
    const auto lines =
        vrflow::testing::readLines(dir.file("display-wall/t" + std::to_string(t) + ".swaps"));
    ASSERT_EQ(lines.size(), static_cast<std::size_t>(kIterations - 1)) << "tile " << t;
    for (int k = 0; k + 1 < kIterations; ++k) {
      EXPECT_EQ(lines[k].substr(0, lines[k].find(' ')), std::to_string(k)) << "tile " << t;
    }
  }
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
  EXPECT_TRUE(vrflow::testing::vrflowShmEntries().empty());
}

// With a swap margin the tiles swap at the latest tile's ready time plus the margin: a tile draws
// frame k after showing k - 1, so no tile shows frame k earlier than the margin after the last
// tile showed k - 1 (without it the lock only orders them).
TEST(DisplayWall, WithASwapMarginNoTileShowsAFrameBeforeTheMarginAfterTheLastShowedThePrevious) {
  TempDir dir;
  const auto file = dir.write("display_wall.xml", application(dir));
  constexpr int kFrames = 6;
  constexpr double kMarginS = 0.1;
  const auto result = vrflow::testing::runCommand(
      {"/bin/sh", "-c",
       "cd '" + dir.path() + "' && exec '" + vrflow::testing::binDir() + "/vrflow' run '" + file +
           "' --composites '" + exampleDir() + "' -n " + std::to_string(kFrames) +
           " --set wall.swap_margin=100 --no-progress"},
      180);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::vector<std::vector<double>> shown(4);
  for (int t = 0; t < 4; ++t) {
    for (const auto& line :
         vrflow::testing::readLines(dir.file("display-wall/t" + std::to_string(t) + ".swaps"))) {
      shown[t].push_back(std::stod(line.substr(line.find(' ') + 1)));
    }
    ASSERT_EQ(shown[t].size(), static_cast<std::size_t>(kFrames - 1)) << "tile " << t;
  }
  for (int k = 1; k + 1 < kFrames; ++k) {
    double last = 0, first = 1e300;
    for (const auto& times : shown) {
      last = std::max(last, times[k - 1]);
      first = std::min(first, times[k]);
    }
    EXPECT_GE(first - last, kMarginS - 1e-4) << "frame " << k;
  }
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
}

// The 4 x 4 example (tiles of 60 x 34 pixels, the small liquid) launched over its four loopback
// hosts with the composites of `composites`, for `frames` iterations; the report.
nlohmann::json launchFourByFour(const TempDir& dir, const std::string& composites, int frames) {
  std::string wall = vrflow::testing::readFile(exampleDir() + "/wall_4x4.wall");
  replaceAll(wall, "pixels 240 135", "pixels 60 34");
  dir.write("wall.wall", wall);
  const auto file =
      dir.write("display_wall_4x4.xml",
                smallExample("display_wall_4x4.xml", "wall_4x4.wall", dir.file("wall.wall")));
  fs::create_directories(dir.file("display-wall-4x4"));
  const auto result = vrflow::testing::runCommand(
      {"/bin/sh", "-c",
       "cd '" + dir.path() + "' && exec '" + vrflow::testing::binDir() + "/vrflow' launch '" +
           file + "' --composites '" + composites + "' -n " + std::to_string(frames) +
           " --no-progress --report report.json"},
      240);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  return nlohmann::json::parse(vrflow::testing::readFile(dir.file("report.json")), nullptr, false);
}

// The host of a node of the 4 x 4 example: a module's from the report; the wall's filters
// `objects-hN`, `ready-hN`, `swap-hN` on hN unless `flat` (every filter on h0, as the composite
// placed them before), every other filter on h0.
std::string hostOf(const nlohmann::json& report, const std::string& endpoint, bool flat) {
  const std::string node = endpoint.substr(0, endpoint.rfind('.'));
  for (const auto& module : report["modules"]) {
    if (module["id"] == node) return module["host"];
  }
  const auto dash = node.rfind("-h");
  if (!flat && node.rfind("wall:", 0) == 0 && dash != std::string::npos) {
    return node.substr(dash + 1);
  }
  return "h0";
}

// Bytes per connection kind crossing from one host to another, by the sending node's name
// without the wall's prefix and host suffix ("objects", "liquid", "swap", "ready", ...).
std::map<std::string, double> bytesCrossingHosts(const nlohmann::json& report, bool flat) {
  std::map<std::string, double> crossing;
  for (const auto& c : report["connections"]) {
    const std::string from = c["from"], to = c["to"];
    if (hostOf(report, from, flat) == hostOf(report, to, flat)) continue;
    std::string kind = from.substr(0, from.rfind('.'));
    if (kind.rfind("wall:", 0) == 0) kind = kind.substr(5);
    if (const auto dash = kind.rfind("-h"); dash != std::string::npos) kind.resize(dash);
    if (kind.size() > 1 && kind[0] == 't' && std::isdigit(static_cast<unsigned char>(kind[1]))) {
      kind = "tile " + c["to"].get<std::string>().substr(c["to"].get<std::string>().rfind('.') + 1);
    }
    crossing[kind] += c["bytes"].get<double>();
  }
  return crossing;
}

// The 4 x 4 example over four loopback hosts: every tile on every host shows frames 0, 1, ...
// in step, and the recorder joins all 16.
TEST(DisplayWall, TheFourByFourWallOverFourLoopbackHostsShowsEveryFrameInStep) {
  TempDir dir;
  constexpr int kFrames = 8;
  const auto report = launchFourByFour(dir, exampleDir(), kFrames);
  ASSERT_FALSE(report.is_discarded());
  EXPECT_EQ(report["timing"]["hosts"], 4);
  for (int t = 0; t < 16; ++t) {
    const auto lines =
        vrflow::testing::readLines(dir.file("display-wall-4x4/t" + std::to_string(t) + ".swaps"));
    ASSERT_EQ(lines.size(), static_cast<std::size_t>(kFrames - 1)) << "tile " << t;
    for (int k = 0; k + 1 < kFrames; ++k) {
      EXPECT_EQ(lines[k].substr(0, lines[k].find(' ')), std::to_string(k)) << "tile " << t;
    }
  }
  const auto mosaic = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-wall-mosaic", dir.file("wall.wall"),
       dir.file("display-wall-4x4"), "--out", dir.file("mosaic")},
      60);
  ASSERT_EQ(mosaic.exitCode, 0) << mosaic.err;
  const auto last = readPng(dir.file("mosaic/wall_000007.png"));
  ASSERT_TRUE(last.ok());
  EXPECT_EQ(last->width, 4 * 60 + 3 * 1);  // 1.5 cm mullions at 60 px per 0.8 m: 1 pixel
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
  EXPECT_TRUE(vrflow::testing::vrflowShmEntries().empty());
}

// The composite's trees per host: the scene and the swap release cross to each remote host once
// and fan out there, so the bytes of the broadcast objects crossing hosts are a quarter of what
// the same wall sends with every filter on h0 (each of the 12 remote tiles its own copy), and the
// tiles get the same bytes either way.
TEST(DisplayWall, FiltersPlacedPerHostSendEachRemoteHostOneCopyInsteadOfOnePerTile) {
  TempDir perHostDir, flatDir;
  constexpr int kFrames = 6;
  const auto perHost = launchFourByFour(perHostDir, exampleDir(), kFrames);
  // The same composite with every filter on h0.
  std::string composite = vrflow::testing::readFile(exampleDir() + "/display_wall.vrc.xml");
  for (const std::string kind : {"broadcast\" host=\"h${h}", "merge\" host=\"h${h}"}) {
    std::string flat = kind;
    replaceAll(flat, "h${h}", "h0");
    replaceAll(composite, kind, flat);
  }
  ASSERT_EQ(composite.find("type=\"broadcast\" host=\"h${h}"), std::string::npos);
  fs::create_directories(flatDir.file("composites"));
  flatDir.write("composites/display_wall.vrc.xml", composite);
  const auto flat = launchFourByFour(flatDir, flatDir.file("composites"), kFrames);
  ASSERT_FALSE(perHost.is_discarded());
  ASSERT_FALSE(flat.is_discarded());
  const auto perHostCrossing = bytesCrossingHosts(perHost, false);
  const auto flatCrossing = bytesCrossingHosts(flat, true);
  double scene = 0;
  for (const auto& c : perHost["connections"]) {
    if (c["to"] == "wall:objects.in") scene = c["bytes"];
  }
  ASSERT_GT(scene, 0);
  // Per host: one copy of the scene to each of h1, h2, h3; flat: one to each of 12 tiles.
  EXPECT_EQ(perHostCrossing.at("objects"), 3 * scene);
  EXPECT_EQ(flatCrossing.at("objects"), 12 * scene);
  EXPECT_EQ(perHostCrossing.at("swap") * 4, flatCrossing.at("swap"));
  // What the tiles are sent does not change: the same bytes into every tile's objects input.
  double perHostTiles = 0, flatTiles = 0;
  for (const auto& c : perHost["connections"]) {
    if (c["to"].get<std::string>().ends_with(".objects")) perHostTiles += c["bytes"].get<double>();
  }
  for (const auto& c : flat["connections"]) {
    if (c["to"].get<std::string>().ends_with(".objects")) flatTiles += c["bytes"].get<double>();
  }
  EXPECT_EQ(perHostTiles, flatTiles);
  double perHostTotal = 0, flatTotal = 0;
  for (const auto& [kind, bytes] : perHostCrossing) perHostTotal += bytes;
  for (const auto& [kind, bytes] : flatCrossing) flatTotal += bytes;
  RecordProperty("bytes_crossing_hosts_per_host", std::to_string(perHostTotal));
  RecordProperty("bytes_crossing_hosts_flat", std::to_string(flatTotal));
  EXPECT_LT(perHostTotal, flatTotal);
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
  EXPECT_TRUE(vrflow::testing::vrflowShmEntries().empty());
}

TEST(DisplayWall, TheRecorderRefusesAMissingTileFrameNamingIt) {
  TempDir dir;
  fs::create_directories(dir.file("frames"));
  Image image;
  image.width = 160;
  image.height = 90;
  image.rgb.assign(160 * 90 * 3, 100);
  dir.write("wall.wall",
            "grid 2 1\npixels 160 90\nsize 1.6 0.9\ntile a 0 0 h :0 0 0\n"
            "tile b 1 0 h :0 0 0\n");
  ASSERT_TRUE(writePng(dir.file("frames/a_000000.png"), image).ok());
  ASSERT_TRUE(writePng(dir.file("frames/b_000000.png"), image).ok());
  ASSERT_TRUE(writePng(dir.file("frames/a_000001.png"), image).ok());
  const auto missing = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-wall-mosaic", dir.file("wall.wall"), dir.file("frames"),
       "--out", dir.file("mosaic")},
      30);
  EXPECT_EQ(missing.exitCode, 2);
  EXPECT_NE(missing.err.find("frame 1 of tile 'b' is missing"), std::string::npos) << missing.err;
  const auto badWall =
      vrflow::testing::runCommand({vrflow::testing::binDir() + "/vrflow-wall-mosaic",
                                   dir.file("nowall.wall"), dir.file("frames")},
                                  30);
  EXPECT_EQ(badWall.exitCode, 2);
  EXPECT_NE(badWall.err.find("nowall.wall"), std::string::npos) << badWall.err;
  fs::remove(dir.file("frames/a_000001.png"));
  dir.write("small.wall",
            "grid 2 1\npixels 16 16\nsize 1.6 0.9\ntile a 0 0 h :0 0 0\n"
            "tile b 1 0 h :0 0 0\n");
  const auto wrongSize = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-wall-mosaic", dir.file("small.wall"),
       dir.file("frames"), "--out", dir.file("mosaic")},
      30);
  EXPECT_EQ(wrongSize.exitCode, 2);
  EXPECT_NE(wrongSize.err.find("160x90"), std::string::npos) << wrongSize.err;
}

}  // namespace
}  // namespace vrflow::viewer
