// The viewer module in a `vrflow run`: frames on disk, bad parameters refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "../runtime/process_helpers.hpp"
#include "vrflow/viewer/frame_writer.hpp"
#include "vrflow/viewer/image.hpp"

namespace vrflow::viewer {
namespace {

namespace fs = std::filesystem;
using vrflow::testing::TempDir;

// The application: bodies -> view, with the viewer's parameters as given.
std::string application(const std::string& viewerParams, const std::string& bodiesParams = "") {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="viewer-test" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="bodies" package="viewer-testing" type="bodies" host="local">)" +
         bodiesParams + R"(</module>
    <module id="view" package="viewer" type="viewer" host="local">)" +
         viewerParams + R"(</module>
  </modules>
  <connections>
    <connection from="bodies.objects" to="view.objects"/>
  </connections>
</application>
)";
}

std::string param(const std::string& name, const std::string& value) {
  return "<param name=\"" + name + "\" value=\"" + value + "\"/>";
}

// Pixels whose channels differ by more than 60: objects, not the grey ground or the pale sky.
int colouredPixels(const Image& image) {
  int coloured = 0;
  for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
    const int r = image.rgb[i], g = image.rgb[i + 1], b = image.rgb[i + 2];
    if (std::max({r, g, b}) - std::min({r, g, b}) > 60) ++coloured;
  }
  return coloured;
}

std::vector<std::string> filesIn(const std::string& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

vrflow::testing::CommandResult run(const TempDir& dir, const std::string& app) {
  const auto file = dir.write("app.xml", app);
  return vrflow::testing::runVrflow({"run", file}, 60);
}

std::string common(const std::string& out) {
  return param("output-dir", out) + param("format", "png") + param("width", "160") +
         param("height", "120") + param("eye", "0 2.5 7") + param("target", "0 1 0");
}

TEST(ViewerModule, WritesOnePngPerIterationOfTheRun) {
  TempDir dir;
  const auto out = dir.file("frames");
  const auto result = run(dir, application(common(out)));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(filesIn(out),
            (std::vector<std::string>{"frame_000000.png", "frame_000001.png", "frame_000002.png",
                                      "frame_000003.png", "frame_000004.png"}));
  EXPECT_NE(result.err.find("PNG frames"), std::string::npos) << result.err;
  const auto first = readPng(out + "/frame_000000.png");
  const auto last = readPng(out + "/frame_000004.png");
  ASSERT_TRUE(first.ok() && last.ok());
  EXPECT_EQ(first->width, 160);
  EXPECT_EQ(first->height, 120);
  EXPECT_NE(first->rgb, last->rgb);        // the objects moved
  EXPECT_GT(colouredPixels(*first), 500);  // the objects are drawn
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
}

TEST(ViewerModule, RendersEveryNthIterationWithAPrefix) {
  TempDir dir;
  const auto out = dir.file("frames");
  const auto result =
      run(dir, application(common(out) + param("every", "2") + param("prefix", "shot"),
                           param("count", "6")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(filesIn(out),
            (std::vector<std::string>{"shot_000000.png", "shot_000001.png", "shot_000002.png"}));
}

TEST(ViewerModule, DeletedObjectDisappearsAndForgedShapeIsLoggedNotFatal) {
  TempDir dir;
  const auto out = dir.file("frames");
  const auto result =
      run(dir, application(common(out), param("delete-at", "2") + param("forged", "true")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("rejected"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("module 'view'"), std::string::npos) << result.err;
  ASSERT_EQ(filesIn(out).size(), 5u);
  // The sphere (about 0.5 m across at 7 m: hundreds of pixels) is gone after iteration 2.
  const auto before = readPng(out + "/frame_000001.png");
  const auto after = readPng(out + "/frame_000003.png");
  ASSERT_TRUE(before.ok() && after.ok());
  EXPECT_GT(colouredPixels(*before), colouredPixels(*after) + 150);
}

TEST(ViewerModule, ScriptedCameraMovesTheView) {
  TempDir dir;
  const auto out = dir.file("frames");
  const auto path = dir.write("camera.txt", "0 0 2.5 7 0 1 0\n4 7 2.5 0 0 1 0 60\n");
  const auto result =
      run(dir, application(common(out) + param("camera-path", path), param("count", "5")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  ASSERT_EQ(filesIn(out).size(), 5u);
}

// bodies -> route -> view, the view's interest back into the route: the messages the view sent
// on `interest` over a run of 5 iterations.
int interestMessages(const std::string& viewerParams) {
  TempDir dir;
  const auto file =
      dir.write("app.xml", R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="viewer-interest" version="1">
  <modules>
    <module id="bodies" package="viewer-testing" type="bodies"/>
    <module id="view" package="viewer" type="viewer">)" +
                               common(dir.file("frames")) + viewerParams + R"(</module>
  </modules>
  <filters>
    <filter id="w" type="route"><param name="initially" value="all"/></filter>
  </filters>
  <connections>
    <connection from="bodies.objects" to="w.in"/>
    <connection from="w.out0" to="view.objects"/>
    <connection from="view.interest" to="w.interest0"/>
  </connections>
</application>
)");
  const auto result =
      vrflow::testing::runVrflow({"run", file, "--report", dir.file("report.json")}, 60);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(filesIn(dir.file("frames")).size(), 5u);
  const auto report = nlohmann::json::parse(vrflow::testing::readFile(dir.file("report.json")));
  for (const auto& c : report["connections"]) {
    if (c["from"] == "view.interest") return c["messages"].get<int>();
  }
  ADD_FAILURE() << "no view.interest connection in the report";
  return -1;
}

TEST(ViewerModule, PublishesItsVolumeAtIterationZeroAndWhenTheCameraMovesIt) {
  EXPECT_EQ(interestMessages(""), 1);  // a fixed camera: once
  // Keys at iterations 0 and 2: the camera moves at iterations 1 and 2, then holds.
  TempDir dir;
  const auto path = dir.write("camera.txt", "0 0 2.5 7 0 1 0\n2 7 2.5 0 0 1 0 60\n");
  EXPECT_EQ(interestMessages(param("camera-path", path)), 3);
}

TEST(ViewerModule, BadParametersStopTheRunNamingModuleAndParameter) {
  struct Case {
    std::string params, name;
  };
  for (const Case& c :
       {Case{param("eye", "0 1 0") + param("target", "0 1 0"), "'eye'"},
        Case{param("camera-path", "/nonexistent/camera.txt"), "'camera-path'"},
        Case{param("width", "3"), "width"}, Case{param("format", "gif"), "format"},
        Case{param("tile", "2 0 2 2"), "parameter 'tile' expects 'COL ROW COLS ROWS'"},
        Case{param("tile", "0 0 2"), "parameter 'tile'"},
        Case{param("interest-box", "0 0 0 1 1"), "parameter 'interest-box'"},
        Case{param("view-depth", "0.01"), "parameter 'view-depth' must be beyond the near plane"},
        Case{param("swap-margin", "-1"), "swap-margin"},
        Case{param("swap-margin", "soon"), "swap-margin"}}) {
    TempDir dir;
    const auto result = run(dir, application(param("output-dir", dir.file("f")) + c.params));
    EXPECT_NE(result.exitCode, 0) << c.params;
    EXPECT_NE(result.err.find(c.name), std::string::npos) << result.err;
    EXPECT_NE(result.err.find("view"), std::string::npos) << result.err;
    EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
  }
}

// The digests of every output port but the viewer's, from a run report.
std::map<std::string, std::string> simulationDigests(const std::string& reportPath) {
  std::map<std::string, std::string> digests;
  const auto report = nlohmann::json::parse(vrflow::testing::readFile(reportPath));
  for (const auto& output : report["outputs"]) {
    if (output["module"] == "view") continue;
    digests[output["module"].get<std::string>() + "." + output["port"].get<std::string>()] =
        output["last_digest"].dump();
  }
  return digests;
}

TEST(ViewerExample, ChainWithAViewerComputesTheSameBitsAsWithout) {
  TempDir dir;
  const std::string source = vrflow::testing::readFile(vrflow::testing::sourceDir() +
                                                       "/nodes/viewer/examples/chain_viewer.xml");
  // The same application without the viewer module and its connection.
  std::string without = source;
  const auto begin = without.find("    <module id=\"view\"");
  const auto end = without.find("</module>", begin);
  ASSERT_NE(begin, std::string::npos);
  without.erase(begin, end + std::string("</module>\n").size() - begin);
  const std::string connection = "    <connection from=\"chain.objects\" to=\"view.objects\"/>\n";
  ASSERT_NE(without.find(connection), std::string::npos);
  without.erase(without.find(connection), connection.size());
  const auto withFile = dir.write("with.xml", source);
  const auto withoutFile = dir.write("without.xml", without);
  const auto run = [&](const std::string& app, const std::string& report) {
    return vrflow::testing::runCommand({"/bin/sh", "-c",
                                        "cd " + dir.path() + " && " + vrflow::testing::binDir() +
                                            "/vrflow run " + app + " -n 60 --report " + report});
  };
  const auto a = run(withFile, dir.file("with.json"));
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const auto b = run(withoutFile, dir.file("without.json"));
  ASSERT_EQ(b.exitCode, 0) << b.err;
  const auto withDigests = simulationDigests(dir.file("with.json"));
  EXPECT_EQ(withDigests.size(), 3u);  // chain.objects, springs.forces, gravity.forces
  for (const auto& [port, digest] : withDigests) EXPECT_NE(digest, "null") << port;
  EXPECT_EQ(withDigests, simulationDigests(dir.file("without.json")));
  EXPECT_EQ(filesIn(dir.file("out/chain-viewer")).size(), 6u);  // iterations 0, 10, ..., 50
}

TEST(ViewerExample, SnapshotWritesTheSampleScene) {
  TempDir dir;
  const auto png = dir.file("snapshot.png");
  const auto result = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-viewer-snapshot", png, "200", "100"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto image = readPng(png);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(image->width, 200);
  EXPECT_EQ(image->height, 100);
  EXPECT_GT(colouredPixels(*image), 300);
}

TEST(ViewerModule, WritesAnMp4WhenFfmpegIsPresent) {
  if (findOnPath("ffmpeg").empty()) GTEST_SKIP() << "ffmpeg is not on PATH; PNG output is tested";
  TempDir dir;
  const auto out = dir.file("video");
  const auto result = run(dir, application(param("output-dir", out) + param("format", "mp4") +
                                           param("width", "160") + param("height", "120")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(filesIn(out), (std::vector<std::string>{"frame.mp4"}));
  EXPECT_GT(fs::file_size(out + "/frame.mp4"), 0u);
  EXPECT_NE(result.err.find("MP4"), std::string::npos) << result.err;
}

// A wall tile fed a tracked head draws exactly what a tile whose wall file puts the fixed eye
// there draws, and not what the file's own eye shows.
TEST(ViewerModule, AWallTileLooksFromTheHeadItReceives) {
  TempDir dir;
  const std::string wall =
      "grid 1 1\npixels 160 90\nsize 1.6 0.9\ncentre 0 1.2 2\ntile w 0 0 h :0 0 0\n";
  dir.write("far.wall", wall + "eye 0 1.5 6\n");
  dir.write("head.wall", wall + "eye 0.8 2 5\n");
  const auto viewer = [&](const std::string& id, const std::string& file) {
    return "<module id=\"" + id + "\" package=\"viewer\" type=\"viewer\" host=\"local\">" +
           param("wall", dir.file(file)) + param("wall-tile", "w") +
           param("output-dir", dir.file("frames")) + param("prefix", id) + param("format", "png") +
           param("supersample", "1") + "</module>";
  };
  const std::string app = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="head-test" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="bodies" package="viewer-testing" type="bodies" host="local"/>
    <module id="tracker" package="viewer-testing" type="head" host="local">)" +
                          param("position", "0.8 2 5") + "</module>" +
                          viewer("tracked", "far.wall") + viewer("placed", "head.wall") +
                          viewer("fixed", "far.wall") + R"(
  </modules>
  <connections>
    <connection from="bodies.objects" to="tracked.objects"/>
    <connection from="bodies.objects" to="placed.objects"/>
    <connection from="bodies.objects" to="fixed.objects"/>
    <connection from="tracker.objects" to="tracked.head"/>
  </connections>
</application>
)";
  const auto result = run(dir, app);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("tile 'w' of wall"), std::string::npos) << result.err;
  for (int k = 0; k < 5; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "_%06d.png", k);
    const auto tracked = readPng(dir.file("frames/tracked") + name);
    const auto placed = readPng(dir.file("frames/placed") + name);
    const auto fixed = readPng(dir.file("frames/fixed") + name);
    ASSERT_TRUE(tracked.ok() && placed.ok() && fixed.ok()) << k;
    EXPECT_EQ(tracked->width, 160);
    EXPECT_EQ(tracked->rgb, placed->rgb) << "frame " << k;
    EXPECT_NE(tracked->rgb, fixed->rgb) << "frame " << k;
  }
}

TEST(ViewerModule, BadWallParametersStopTheRunNamingThem) {
  TempDir dir;
  dir.write("w.wall", "grid 1 1\ntile w 0 0 h :0 0 0\n");
  dir.write("broken.wall", "grid 1 1\nsize 1\ntile w 0 0 h :0 0 0\n");
  const auto out = dir.file("frames");
  const auto unknownTile = run(dir, application(common(out) + param("wall", dir.file("w.wall")) +
                                                param("wall-tile", "nope")));
  EXPECT_NE(unknownTile.exitCode, 0);
  EXPECT_NE(unknownTile.err.find("parameter 'wall-tile' names no tile"), std::string::npos)
      << unknownTile.err;
  const auto conflict = run(dir, application(common(out) + param("wall", dir.file("w.wall")) +
                                             param("wall-tile", "w") + param("tile", "0 0 2 2")));
  EXPECT_NE(conflict.err.find("parameter 'tile' conflicts with 'wall'"), std::string::npos)
      << conflict.err;
  const auto broken = run(dir, application(common(out) + param("wall", dir.file("broken.wall")) +
                                           param("wall-tile", "w")));
  EXPECT_NE(broken.exitCode, 0);
  EXPECT_NE(broken.err.find("broken.wall:2: 'size' expects"), std::string::npos) << broken.err;
  const auto lonely = run(dir, application(common(out) + param("wall-tile", "w")));
  EXPECT_NE(lonely.err.find("parameter 'wall-tile' needs 'wall'"), std::string::npos) << lonely.err;
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
  EXPECT_TRUE(vrflow::testing::vrflowShmEntries().empty());
}

}  // namespace
}  // namespace vrflow::viewer
