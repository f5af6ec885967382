// The on-screen viewer in `vrflow run`s under an Xvfb the tests start: a window's events
// arrive on `events` with the world ray through the clicked point; tiles swap-locked through
// merge and broadcast filters show one iteration at a time; a dying tile stops the run cleanly.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include "../runtime/process_helpers.hpp"
#include "vrflow/viewer/view_volume.hpp"
#include "xvfb.hpp"

namespace vrflow::viewer {
namespace {

using testing::Background;
using testing::Xvfb;
using vrflow::testing::TempDir;

std::string param(const std::string& name, const std::string& value) {
  return "<param name=\"" + name + "\" value=\"" + value + "\"/>";
}

std::string header(int count) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="screen-test" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="bodies" package="viewer-testing" type="bodies" host="local">)" +
         param("count", std::to_string(count)) + "</module>\n";
}

// A viewer on screen: 160 x 100 pixels, supersample 1, the viewer tests' camera.
std::string viewer(const std::string& id, const std::string& display, const std::string& window,
                   const std::string& tile, const std::string& extra) {
  return "    <module id=\"" + id + "\" package=\"viewer\" type=\"viewer\" host=\"local\">" +
         param("display", display) + param("window", window) + param("tile", tile) +
         param("width", "160") + param("height", "100") + param("supersample", "1") +
         param("eye", "0 2.5 7") + param("target", "0 1 0") + extra + "</module>\n";
}

vrflow::testing::CommandResult run(const TempDir& dir, const std::string& app) {
  return vrflow::testing::runVrflow({"run", dir.write("app.xml", app)}, 120);
}

Background start(const TempDir& dir, const std::string& app) {
  return Background(
      {vrflow::testing::binDir() + "/vrflow", "--packages",
       vrflow::testing::binDir() + "/../test-packages", "run", dir.write("app.xml", app)},
      dir.file("run.log"));
}

bool waitUntil(const std::function<bool()>& done, double seconds) {
  for (int i = 0; i < static_cast<int>(seconds * 100); ++i) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

void expectNothingLeft() {
  EXPECT_TRUE(vrflow::testing::leftoverProcesses().empty());
  EXPECT_TRUE(vrflow::testing::vrflowShmEntries().empty());
}

class ScreenRun : public ::testing::Test {
 protected:
  // Each test its own display of this helper's range (33-39), two screens.
  void startServer(int number) {
    std::string why;
    auto started = Xvfb::start(number, {{400, 300}, {400, 300}}, why);
    if (!started) GTEST_SKIP() << "no X server for on-screen tests: " << why;
    server_.emplace(std::move(*started));
  }
  std::optional<Xvfb> server_;
};

// A click on the pixel where a known world point projects (the pinhole projection of the tile's
// off-axis frustum, worked out here) arrives with a ray passing through that point.
TEST_F(ScreenRun, AClickArrivesOnEventsWithTheWorldRayThroughTheClickedPoint) {
  startServer(34);
  TempDir dir;
  const auto events = dir.file("events.txt");
  auto app = header(1000000) +
             viewer("view", server_->display(1), "30 40", "1 0 2 2", param("format", "none")) +
             R"(    <module id="rec" package="viewer-testing" type="events" host="local">)" +
             param("file", events) + R"(</module>
  </modules>
  <connections>
    <connection from="bodies.objects" to="view.objects"/>
    <connection from="view.events" to="rec.events"/>
  </connections>
</application>
)";
  auto runner = start(dir, app);
  ASSERT_EQ(
      vrflow::testing::runCommand({"/usr/bin/env", "DISPLAY=" + server_->display(1), "xdotool",
                                   "search", "--sync", "--onlyvisible", "--name", "vrflow view"},
                                  30)
          .exitCode,
      0)
      << vrflow::testing::readFile(dir.file("run.log"));

  // The camera: eye (0, 2.5, 7) towards (0, 1, 0), fov 45; tile 1 0 of a 2 x 2 wall of
  // 160 x 100 tiles: the upper right quarter of a 320 x 200 view.
  Camera camera;
  camera.eye = {0, 2.5, 7};
  camera.target = {0, 1, 0};
  const msg::Vec3 point{0.8, 1.6, 0.3};
  const ViewBasis b = viewBasis(camera);
  const auto dot = [](const msg::Vec3& u, const msg::Vec3& v) {
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  };
  const msg::Vec3 v{point[0] - camera.eye[0], point[1] - camera.eye[1], point[2] - camera.eye[2]};
  const double depth = dot(v, b.forward);
  const double halfHeight = std::tan(22.5 * M_PI / 180.0);  // at unit depth
  const double halfWidth = halfHeight * 320.0 / 200.0;
  // Whole-view pixels of the point, then this tile's (columns 160.., rows 0..).
  const double px = (dot(v, b.side) / depth / halfWidth + 1.0) * 160.0 - 160.0;
  const double py = (1.0 - dot(v, b.up) / depth / halfHeight) * 100.0;
  ASSERT_GT(px, 0.0);
  ASSERT_LT(px, 160.0);
  ASSERT_GT(py, 0.0);
  ASSERT_LT(py, 100.0);
  const int x = static_cast<int>(std::lround(px)), y = static_cast<int>(std::lround(py));
  ASSERT_EQ(testing::xdotool(server_->display(1),
                             {"mousemove", "--screen", "1", "--sync", std::to_string(30 + x),
                              std::to_string(40 + y), "click", "1", "key", "q"}),
            0);
  std::vector<std::string> lines;
  const bool gotKey = waitUntil(
      [&] {
        lines = vrflow::testing::readLines(events);
        return std::find(lines.begin(), lines.end(), "key 81 1") != lines.end();
      },
      30);
  runner.signal(SIGINT);
  const auto status = runner.wait(30);
  ASSERT_TRUE(gotKey) << vrflow::testing::readFile(dir.file("run.log"));
  ASSERT_TRUE(status.has_value()) << "the run did not stop on SIGINT";
  int presses = 0;
  for (const auto& line : lines) {
    std::istringstream in(line);
    std::string kind;
    unsigned action = 0, button = 0, buttons = 0;
    double ex = 0, ey = 0;
    msg::Vec3 origin{}, direction{};
    in >> kind;
    if (kind != "pointer") continue;
    in >> action >> button >> buttons >> ex >> ey >> origin[0] >> origin[1] >> origin[2] >>
        direction[0] >> direction[1] >> direction[2];
    if (action != 1) continue;  // Press
    ++presses;
    EXPECT_EQ(ex, x);
    EXPECT_EQ(ey, y);
    EXPECT_NEAR(std::sqrt(dot(direction, direction)), 1.0, 1e-12);
    // The distance from the point to the ray is at most the footprint of the half pixel
    // between the projection and the clicked pixel: 2 * halfHeight * depth / 200 per pixel.
    const msg::Vec3 w{point[0] - origin[0], point[1] - origin[1], point[2] - origin[2]};
    const double along = dot(w, direction);
    const double off = std::sqrt(std::max(0.0, dot(w, w) - along * along));
    EXPECT_GT(along, 0.0);
    EXPECT_LE(off, 0.71 * 2.0 * halfHeight * depth / 200.0) << line;
  }
  EXPECT_EQ(presses, 1) << vrflow::testing::readFile(events);
  server_.reset();
  expectNothingLeft();
}

TEST(ScreenParams, BadWindowParametersStopTheRunNamingModuleAndParameter) {
  TempDir dir;
  const auto tail = R"(  </modules>
  <connections><connection from="bodies.objects" to="view.objects"/></connections>
</application>
)";
  const auto badPlace = run(dir, header(3) + viewer("view", ":39.0", "12", "0 0 1 1", "") + tail);
  EXPECT_NE(badPlace.exitCode, 0);
  EXPECT_NE(badPlace.err.find("module 'view' (viewer/viewer): parameter 'window'"),
            std::string::npos)
      << badPlace.err;
  const auto noWindow = run(dir, header(3) + viewer("view", ":39.0", "", "0 0 1 1", "") + tail);
  EXPECT_NE(noWindow.exitCode, 0);
  EXPECT_NE(noWindow.err.find("parameter 'display'"), std::string::npos) << noWindow.err;
  const auto supersampled = run(
      dir, header(3) + viewer("view", ":39.0", "0 0", "0 0 1 1", param("supersample", "2")) + tail);
  EXPECT_NE(supersampled.exitCode, 0);
  EXPECT_NE(supersampled.err.find("parameter 'supersample'"), std::string::npos)
      << supersampled.err;
  // Nobody answers on :39.5 (the test leaves this helper's last display free).
  const auto deaf = run(dir, header(3) + viewer("view", ":39.5", "0 0", "0 0 1 1", "") + tail);
  EXPECT_NE(deaf.exitCode, 0);
  EXPECT_NE(deaf.err.find("display ':39.5'"), std::string::npos) << deaf.err;
  expectNothingLeft();
}

// n tiles of a COLS x ROWS wall, their `ready` joined by a heap of `merge` filters (fan-in f)
// and the release brought back by a heap of `broadcast` filters (fan-out f): the swap-lock.
std::string swapLockedWall(const Xvfb& server, const TempDir& dir, int cols, int rows, int fan,
                           int count) {
  const int n = cols * rows;
  const int inner = (n - 1 + fan - 2) / (fan - 1);  // filters of a heap with n leaves
  std::string app = header(count);
  for (int i = 0; i < n; ++i) {
    const std::string id = "tile" + std::to_string(i);
    app += viewer(id, server.display(i % 2),
                  std::to_string(170 * (i / 2 % 2)) + " " + std::to_string(110 * (i / 4)),
                  std::to_string(i % cols) + " " + std::to_string(i / cols) + " " +
                      std::to_string(cols) + " " + std::to_string(rows),
                  param("format", "none") + param("swap-log", dir.file(id + ".swaps")) +
                      "<input port=\"swap\" initial-messages=\"1\"/>");
  }
  app += "  </modules>\n  <filters>\n";
  const auto children = [&](int p) {
    std::vector<int> c;
    for (int k = p * fan + 1; k <= p * fan + fan && k < inner + n; ++k) c.push_back(k);
    return c;
  };
  for (int p = 0; p < inner; ++p) {
    app += "    <filter id=\"m" + std::to_string(p) + "\" type=\"merge\" host=\"local\">" +
           param("inputs", std::to_string(children(p).size())) +
           param("stamps", "frame-min:min, frame-max:max") + "</filter>\n";
    app += "    <filter id=\"b" + std::to_string(p) + "\" type=\"broadcast\" host=\"local\"/>\n";
  }
  app += "  </filters>\n  <connections>\n";
  for (int i = 0; i < n; ++i) {
    app +=
        "    <connection from=\"bodies.objects\" to=\"tile" + std::to_string(i) + ".objects\"/>\n";
  }
  for (int p = 0; p < inner; ++p) {
    const auto c = children(p);
    for (std::size_t k = 0; k < c.size(); ++k) {
      const bool leaf = c[k] >= inner;
      const std::string tile = "tile" + std::to_string(c[k] - inner);
      app += "    <connection from=\"" +
             (leaf ? tile + ".ready" : "m" + std::to_string(c[k]) + ".out") + "\" to=\"m" +
             std::to_string(p) + ".in" + std::to_string(k) + "\"/>\n";
      app += "    <connection from=\"b" + std::to_string(p) + ".out\" to=\"" +
             (leaf ? tile + ".swap" : "b" + std::to_string(c[k]) + ".in") + "\"/>\n";
    }
  }
  app += "    <connection from=\"m0.out\" to=\"b0.in\"/>\n  </connections>\n</application>\n";
  return app;
}

struct Swap {
  std::uint64_t frame = 0;
  double seconds = 0;
};

std::vector<Swap> swapsOf(const std::string& file) {
  std::vector<Swap> swaps;
  for (const auto& line : vrflow::testing::readLines(file)) {
    std::istringstream in(line);
    Swap s;
    if (in >> s.frame >> s.seconds) swaps.push_back(s);
  }
  return swaps;
}

// Eight tiles (4 x 2) on two screens, a heap of fan-in 2 (three levels of merges): every set of
// swaps shows one iteration, in order, none skipped.
TEST_F(ScreenRun, EverySetOfSwappedImagesCarriesOneIteration) {
  startServer(35);
  TempDir dir;
  constexpr int kCount = 25;
  const auto result = run(dir, swapLockedWall(*server_, dir, 4, 2, 2, kCount));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("swap-locked"), std::string::npos) << result.err;
  std::vector<std::vector<Swap>> tiles;
  for (int i = 0; i < 8; ++i)
    tiles.push_back(swapsOf(dir.file("tile" + std::to_string(i) + ".swaps")));
  std::vector<double> skews;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    // Frame k is shown at iteration k + 1: the last frame drawn is never released.
    ASSERT_EQ(tiles[t].size(), static_cast<std::size_t>(kCount - 1)) << "tile " << t;
    for (std::size_t k = 0; k < tiles[t].size(); ++k) {
      EXPECT_EQ(tiles[t][k].frame, k) << "tile " << t;
    }
  }
  for (std::size_t k = 0; k + 1 < kCount; ++k) {
    double lo = 1e300, hi = -1e300;
    for (const auto& tile : tiles) {
      lo = std::min(lo, tile[k].seconds);
      hi = std::max(hi, tile[k].seconds);
    }
    skews.push_back(hi - lo);
  }
  std::sort(skews.begin(), skews.end());
  RecordProperty("swap_skew_us_p50", static_cast<int>(1e6 * skews[skews.size() / 2]));
  RecordProperty("swap_skew_us_max", static_cast<int>(1e6 * skews.back()));
  // A tile never shows frame k + 1 before every tile has drawn frame k + 1, which is after
  // every tile showed frame k: the swap of k + 1 anywhere follows the swap of k everywhere.
  for (std::size_t k = 0; k + 2 < kCount; ++k) {
    double lastOfK = -1e300, firstOfNext = 1e300;
    for (const auto& tile : tiles) {
      lastOfK = std::max(lastOfK, tile[k].seconds);
      firstOfNext = std::min(firstOfNext, tile[k + 1].seconds);
    }
    EXPECT_LT(lastOfK, firstOfNext) << "frame " << k;
  }
  server_.reset();
  expectNothingLeft();
}

bool descendsFrom(pid_t pid, pid_t ancestor,
                  const std::vector<vrflow::testing::ProcessInfo>& table) {
  for (int depth = 0; depth < 16 && pid > 1; ++depth) {
    if (pid == ancestor) return true;
    const auto it =
        std::find_if(table.begin(), table.end(), [&](const auto& p) { return p.pid == pid; });
    if (it == table.end()) return false;
    pid = it->parent;
  }
  return false;
}

// One tile's process dies mid-run (as when its host goes): the others wait at the barrier, and
// the run stops with an error naming that tile, leaving no process or segment behind.
TEST_F(ScreenRun, ATileThatDiesStopsTheSwapLockedRunCleanly) {
  startServer(36);
  TempDir dir;
  auto runner = start(dir, swapLockedWall(*server_, dir, 2, 2, 2, 1000000));
  ASSERT_TRUE(waitUntil([&] { return swapsOf(dir.file("tile2.swaps")).size() >= 5; }, 60))
      << vrflow::testing::readFile(dir.file("run.log"));
  pid_t victim = 0;
  const auto table = vrflow::testing::processTable();
  for (const auto& p : table) {
    if (p.name != "vrflow-viewer" || !descendsFrom(p.pid, runner.pid(), table)) continue;
    std::ifstream cmd("/proc/" + std::to_string(p.pid) + "/environ");
    std::stringstream text;
    text << cmd.rdbuf();
    if (text.str().find("VRFLOW_MODULE_ID=tile2") != std::string::npos) victim = p.pid;
  }
  ASSERT_GT(victim, 0) << "no vrflow-viewer process of tile2 under the run";
  kill(victim, SIGKILL);
  const auto status = runner.wait(60);
  ASSERT_TRUE(status.has_value()) << "the run did not stop after a tile died";
  EXPECT_NE(*status, 0);
  const auto log = vrflow::testing::readFile(dir.file("run.log"));
  EXPECT_NE(log.find("tile2"), std::string::npos) << log;
  server_.reset();
  expectNothingLeft();
}

}  // namespace
}  // namespace vrflow::viewer
