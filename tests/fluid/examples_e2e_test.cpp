// examples/dam_break and examples/buoyancy through the real `vrflow run`, with the rigid
// package's animator, contacts and gravity: the example files themselves (example_apps.hpp
// takes the viewer out and overrides what a test changes).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>  // unsetenv
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "example_apps.hpp"

namespace vrflow::testing {
namespace {

using nlohmann::json;

json readJson(const std::string& path) {
  return json::parse(readFile(path));
}

// Waits until no child of this process (orphans of the runs come back to it) is running, at
// most `seconds`; zombies do not count. True when none runs.
bool runningChildrenGone(double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    bool running = false;
    for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
      const std::string pid = entry.path().filename().string();
      if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
      std::ifstream stat(entry.path() / "stat");
      std::string line;
      std::getline(stat, line);
      const auto close = line.rfind(')');
      if (close == std::string::npos) continue;
      std::istringstream rest(line.substr(close + 2));
      char state = 0;
      int ppid = 0;
      rest >> state >> ppid;
      if (ppid == getpid() && state != 'Z') running = true;
    }
    if (!running) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// Processes the runs left behind, as one line for a failure message.
std::string leftovers() {
  std::string text;
  for (const auto& line : leftoverProcesses()) text += line + "; ";
  return text;
}

double distance(const json& a, const json& b) {
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = a[k].get<double>() - b[k].get<double>();
    sum += d * d;
  }
  return std::sqrt(sum);
}

// The volume column (7th) of the fluid module's stats CSV.
std::vector<double> volumes(const std::string& path) {
  std::vector<double> out;
  const auto lines = readLines(path);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::stringstream in(lines[i]);
    std::string cell;
    for (int c = 0; c < 7 && std::getline(in, cell, ','); ++c) {
    }
    out.push_back(std::stod(cell));
  }
  return out;
}

// The dam break as shipped (40 x 24 x 16 cells, 20,480 particles) for 1000 steps of 0.01 s.
TEST(DamBreakExample, KeepsItsVolumeWithinTwoPercentOverAThousandSteps) {
  TempDir dir;
  const auto result = runApp(dir, exampleForTest("dam_break", "dam_break.xml", {}), 1000, 300);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto fluid = readJson(dir.file("dam_break-fluid.json"));
  EXPECT_EQ(fluid["steps"].get<int>(), 1000);
  EXPECT_EQ(fluid["particles"].get<int>(), 20480) << "no particle lost";
  const double v0 = fluid["initialVolume"].get<double>(), v = fluid["volume"].get<double>();
  EXPECT_NEAR(v0, 0.5 * 0.8 * 0.8, 1e-9) << "the column as filled";
  const auto all = volumes(dir.file("dam_break-stats.csv"));
  ASSERT_EQ(all.size(), 1000u);
  double swing = 0.0;
  for (const double x : all) swing = std::max(swing, std::abs(x / v0 - 1.0));
  std::printf(
      "dam break: volume %.5f -> %.5f m^3 (%+.2f %%) after 1000 steps, largest swing "
      "%.2f %%\n",
      v0, v, 100.0 * (v / v0 - 1.0), 100.0 * swing);
  EXPECT_NEAR(v / v0, 1.0, 0.02);
  // The column broke: the liquid spread over the tank, lower than it started, and came to rest.
  const double cx = fluid["centroid"][0].get<double>(), cy = fluid["centroid"][1].get<double>();
  std::printf("dam break: centroid x %.3f (from 0.25), y %.3f (from 0.40), level %.3f m\n", cx, cy,
              fluid["level"].get<double>());
  EXPECT_GT(cx, 0.8);
  EXPECT_LT(cy, 0.2);
  EXPECT_LT(fluid["maxSpeed"].get<double>(), 1.0);
  // The wave reached the crates and moved them; they stayed in the tank and on or above the floor.
  const auto bodies = readJson(dir.file("dam_break-bodies.json"));
  const std::vector<std::vector<double>> crateStarts{{1.45, 0.1, 0.2}, {1.65, 0.1, 0.6}};
  int crate = 0;
  for (const auto& b : bodies["bodies"]) {
    if (b["kinematic"].get<bool>()) continue;
    ASSERT_LT(crate, 2);
    EXPECT_GT(distance(b["position"], json(crateStarts[static_cast<std::size_t>(crate)])), 0.05)
        << "crate " << crate << " was not moved by the wave";
    EXPECT_GT(b["boundsMin"][1].get<double>(), -0.012) << "crate " << crate << " below the floor";
    for (int k : {0, 2}) {
      EXPECT_GT(b["boundsMin"][k].get<double>(), -0.01) << "crate " << crate << " left the tank";
    }
    EXPECT_LT(b["boundsMax"][0].get<double>(), 2.01) << "crate " << crate << " left the tank";
    EXPECT_LT(b["boundsMax"][2].get<double>(), 0.81) << "crate " << crate << " left the tank";
    ++crate;
  }
  EXPECT_EQ(crate, 2);
  EXPECT_EQ(leftovers(), "");
}

// Two MPI blocks (vrflow starts the module as 2 ranks through mpirun) against one, over the
// first 100 steps of the dam break: the kinematic ground, walls and pillar must reach both
// blocks (they did not: a worker took them for dynamic bodies of mass 0, refused the step alone
// and left the module waiting in a collective call until vrflow's --timeout). The blocks differ
// in the last bits (block-Jacobi preconditioner), and the breaking wave and the crates' contacts
// amplify that: measured gaps on the crates' positions 1e-6 m after 60 steps, 1.6e-3 m after 100,
// 5e-2 m after 150. Tolerances after 100 steps: particle count equal, volume within 0.5 %,
// particle centroid within 2 mm, crates within 1 cm.
TEST(DamBreakExample, TwoBlocksAgreeWithOneWithKinematicBodiesInTheTank) {
  json fluid[2], bodies[2];
  for (int run = 0; run < 2; ++run) {
    TempDir dir;
    const auto app =
        exampleForTest("dam_break", "dam_break.xml", {{"water.blocks", std::to_string(run + 1)}});
    const auto result = runApp(dir, app, 100, 120);
    ASSERT_EQ(result.exitCode, 0) << run + 1 << " blocks: " << result.err;
    fluid[run] = readJson(dir.file("dam_break-fluid.json"));
    bodies[run] = readJson(dir.file("dam_break-bodies.json"));
    // A process of the run that vrflow did not wait for (an MPI rank that mpirun left ending)
    // may exit just after vrflow returns: give it 5 s, then only processes still running count.
    EXPECT_TRUE(runningChildrenGone(5.0)) << "a process of the run outlived it by 5 s";
    for (const auto& line : leftoverProcesses()) {
      EXPECT_NE(line.find("(reaped)"), std::string::npos) << "still running: " << line;
    }
  }
  EXPECT_EQ(fluid[1]["particles"], fluid[0]["particles"]);
  const double v1 = fluid[0]["volume"].get<double>(), v2 = fluid[1]["volume"].get<double>();
  const double centroidGap = distance(fluid[0]["centroid"], fluid[1]["centroid"]);
  double crateGap = 0.0;
  ASSERT_EQ(bodies[0]["bodies"].size(), bodies[1]["bodies"].size());
  for (std::size_t b = 0; b < bodies[0]["bodies"].size(); ++b) {
    crateGap = std::max(
        crateGap, distance(bodies[0]["bodies"][b]["position"], bodies[1]["bodies"][b]["position"]));
  }
  std::printf(
      "dam break, 100 steps, 2 blocks vs 1: volume %+.4f %%, centroid %.2e m, crates "
      "%.2e m\n",
      100.0 * (v2 / v1 - 1.0), centroidGap, crateGap);
  EXPECT_NEAR(v2 / v1, 1.0, 0.005);
  EXPECT_LT(centroidGap, 0.002);
  EXPECT_LT(crateGap, 0.01);
  // The comparison is of a moving scene: the column has started to break.
  EXPECT_GT(fluid[0]["centroid"][0].get<double>(), 0.4);
}

// The paper's parallel module: examples/dam_break/dam_break_blocks.xml runs the fluid as two
// modules of one MPI job (composite fluid_blocks: a route filter feeds each block the bodies
// near its slab, gather filters join forces and particles). Each block holds only the bodies
// near it, combines per-body sums with the others by id, and the lowest block holding a body
// reports its force; that is the same arithmetic as the fluid's own blocks (every block holding
// every body), so after 100 steps the two agree bit for bit: particles, volume, centroid, every
// body's position, and the forces of the last step. With 2 blocks as shipped, and with 4 set on
// the command line (`--set water.blocks=4` sets the composite instance's parameter).
void expectOneModulePerBlockEqualsOwnBlocks(int blockCount) {
  const std::string blocks = std::to_string(blockCount);
  json fluid[2], bodies[2];
  for (int run = 0; run < 2; ++run) {
    TempDir dir;
    const auto app = run == 0
                         ? exampleForTest("dam_break", "dam_break.xml", {{"water.blocks", blocks}})
                         : exampleForTest("dam_break", "dam_break_blocks.xml", {});
    const auto result = runApp(dir, app, 100, 120, run == 0 ? "" : "--set water.blocks=" + blocks);
    ASSERT_EQ(result.exitCode, 0) << (run == 0 ? "blocks = " : "fluid_blocks ") << blocks << ": "
                                  << result.err;
    const std::string prefix = run == 0 ? "dam_break" : "dam_break_blocks";
    fluid[run] = readJson(dir.file(prefix + "-fluid.json"));
    bodies[run] = readJson(dir.file(prefix + "-bodies.json"));
    if (run == 1) {
      // Two fluid modules ran, each with its own ports: the report lists both.
      const auto report = readJson(dir.file("report.json"));
      int modules = 0;
      for (const auto& module : report["modules"]) {
        const std::string id = module["id"].get<std::string>();
        if (id.rfind("water:block", 0) == 0) {
          ++modules;
          EXPECT_EQ(module["iterations"].get<int>(), 100) << id;
        }
      }
      EXPECT_EQ(modules, blockCount) << report.dump();
    }
    EXPECT_TRUE(runningChildrenGone(5.0)) << "a process of the run outlived it by 5 s";
    for (const auto& line : leftoverProcesses()) {
      EXPECT_NE(line.find("(reaped)"), std::string::npos) << "still running: " << line;
    }
  }
  EXPECT_EQ(fluid[1]["particles"], fluid[0]["particles"]);
  EXPECT_EQ(fluid[1]["volume"], fluid[0]["volume"]);
  EXPECT_EQ(fluid[1]["centroid"], fluid[0]["centroid"]);
  EXPECT_EQ(fluid[1]["maxSpeed"], fluid[0]["maxSpeed"]);
  ASSERT_EQ(fluid[1]["bodies"].size(), fluid[0]["bodies"].size());
  // Bodies in id order; the ids themselves differ (other modules take other id ranges).
  for (std::size_t b = 0; b < fluid[0]["bodies"].size(); ++b) {
    EXPECT_EQ(fluid[1]["bodies"][b]["position"], fluid[0]["bodies"][b]["position"]) << b;
    EXPECT_EQ(fluid[1]["bodies"][b]["force"], fluid[0]["bodies"][b]["force"]) << b;
    EXPECT_EQ(fluid[1]["bodies"][b]["torque"], fluid[0]["bodies"][b]["torque"]) << b;
    EXPECT_EQ(fluid[1]["bodies"][b]["faces"], fluid[0]["bodies"][b]["faces"]) << b;
  }
  ASSERT_EQ(bodies[1]["bodies"].size(), bodies[0]["bodies"].size());
  for (std::size_t b = 0; b < bodies[0]["bodies"].size(); ++b) {
    EXPECT_EQ(bodies[1]["bodies"][b]["position"], bodies[0]["bodies"][b]["position"]) << b;
  }
  // The comparison is of a moving scene: the column has started to break.
  EXPECT_GT(fluid[0]["centroid"][0].get<double>(), 0.4);
}

TEST(DamBreakExample, OneFluidModulePerBlockEqualsTheFluidsOwnBlocks) {
  expectOneModulePerBlockEqualsOwnBlocks(2);
}

TEST(DamBreakExample, FourFluidModulesEqualTheFluidsOwnFourBlocks) {
  expectOneModulePerBlockEqualsOwnBlocks(4);
}

// A flat box of density 500 settles with about half its height under water; a cube of density
// 2000 rests on the floor. Tolerance on the submerged fraction: +- 0.15 (the surface is known to
// a particle layer, a quarter of a 0.05 m cell, on a 0.3 m box; bodies are rasterised by cell).
TEST(BuoyancyExample, LightBoxFloatsHalfSubmergedAndHeavyBoxRestsOnTheFloor) {
  TempDir dir;
  const auto result = runApp(dir, exampleForTest("buoyancy", "buoyancy.xml", {}), 400, 240);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto fluid = readJson(dir.file("buoyancy-fluid.json"));
  const auto bodies = readJson(dir.file("buoyancy-bodies.json"));
  // Scene order: ground, 4 walls, light, heavy (the fluid lists bodies in id order: the same).
  ASSERT_EQ(bodies["bodies"].size(), 7u);
  ASSERT_EQ(fluid["bodies"].size(), 7u);
  const auto& light = bodies["bodies"][5];
  const auto& heavy = bodies["bodies"][6];
  const double level = fluid["level"].get<double>();
  const double submerged = fluid["bodies"][5]["submerged"].get<double>();
  std::printf(
      "buoyancy after 400 steps: level %.3f m, light box %.3f..%.3f m, submerged %.3f, "
      "heavy box bottom %.4f m\n",
      level, light["boundsMin"][1].get<double>(), light["boundsMax"][1].get<double>(), submerged,
      heavy["boundsMin"][1].get<double>());
  EXPECT_NEAR(submerged, 0.5, 0.15);
  EXPECT_LT(std::abs(light["linearVelocity"][1].get<double>()), 0.05) << "settled";
  // Upright: a flat box of half the water's density is stable on its broad face; it rocks in
  // the closed tank, by up to 10 degrees at times (0.38 m high; 0.5 m on its side).
  EXPECT_NEAR(light["boundsMax"][1].get<double>() - light["boundsMin"][1].get<double>(), 0.3, 0.1);
  // The heavy cube on the floor (the ground's top face is at y = -0.002), at rest.
  EXPECT_LT(heavy["boundsMin"][1].get<double>(), 0.01);
  EXPECT_GT(heavy["boundsMin"][1].get<double>(), -0.012);
  EXPECT_LT(std::abs(heavy["linearVelocity"][1].get<double>()), 0.05);
  EXPECT_EQ(leftovers(), "");
}

// The paper scene with the liquid and the net at its true 8 kg (issue 26): 300 iterations (3 s at
// dt 0.01) stay stable. Every node finite, under 1.5 m/s at the end, inside the net's box; the
// water's volume within the fluid's 2 %, no particle out of the grid; the objects sane.
TEST(PaperSceneFluidExample, NetAtItsTrueMassStaysStableThreeSecondsWithTheWater) {
  TempDir dir;
  const auto result =
      runApp(dir, exampleForTest("paper_scene", "paper_scene_fluid.xml", {}), 300, 400);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::ifstream netFile(dir.file("net-final.txt"));
  std::string word;
  int version = 0, nodes = 0;
  netFile >> word >> version >> word >> nodes;
  ASSERT_EQ(nodes, 400);
  double totalMass = 0.0, fastest = 0.0, lowest = 1e9, highest = -1e9;
  for (int i = 0; i < nodes; ++i) {
    double x[3], mass = 0.0, v[3];
    int pinned = 0;
    netFile >> x[0] >> x[1] >> x[2] >> mass >> pinned >> v[0] >> v[1] >> v[2];
    ASSERT_TRUE(netFile.good()) << "node " << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(std::isfinite(x[k]) && std::isfinite(v[k])) << "node " << i;
    }
    totalMass += mass;
    fastest = std::max(fastest, std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    lowest = std::min(lowest, x[1]);
    highest = std::max(highest, x[1]);
    // The net's box: its 1.9 m square between the pinned corners, 5 cm either side.
    EXPECT_TRUE(x[0] >= 0.25 && x[0] <= 2.25 && std::abs(x[2]) <= 1.0) << "node " << i;
  }
  const auto fluid = readJson(dir.file("fluid-final.json"));
  const double v0 = fluid["initialVolume"].get<double>(), v = fluid["volume"].get<double>();
  std::printf(
      "paper scene, 8 kg net, 300 iterations: nodes y %.3f..%.3f, fastest node %.3f m/s, volume "
      "%+.2f %%, fastest particle %.2f m/s\n",
      lowest, highest, fastest, 100.0 * (v / v0 - 1.0), fluid["maxSpeed"].get<double>());
  EXPECT_NEAR(totalMass, 8.0, 1e-9);
  // The net bobs on the water where the objects landed: its fastest node at 2.5-3.5 s is 0.68-1.03
  // m/s (measured at 250, 280, 300, 320 and 350 iterations, 2026-11-27; which of them passes
  // 1.0 changes with the rounding of the rigid/net solve). The unstable coupling this test guards
  // against threw nodes about at several m/s.
  EXPECT_LT(fastest, 1.5);
  EXPECT_GT(lowest, 0.5);  // held by the water (the pool is 0.85 m deep), not through it
  EXPECT_LE(highest, 0.95 + 1e-9);
  EXPECT_NEAR(v / v0, 1.0, 0.02);
  EXPECT_LT(fluid["maxSpeed"].get<double>(), 5.0);
  const double gridMin[3] = {0.25, 0.0, -1.0}, gridMax[3] = {2.25, 4.0, 1.0};
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(fluid["particlesMin"][k].get<double>(), gridMin[k]);
    EXPECT_LE(fluid["particlesMax"][k].get<double>(), gridMax[k]);
  }
  const auto bodies = readJson(dir.file("bodies-final.json"));
  for (const auto& b : bodies["bodies"]) {
    if (b["kinematic"].get<bool>()) continue;
    EXPECT_GT(b["boundsMin"][1].get<double>(), -0.012) << "below the ground";
    EXPECT_LT(b["boundsMax"][1].get<double>(), 1.6) << "thrown up";
  }
  EXPECT_EQ(leftovers(), "");
}

}  // namespace
}  // namespace vrflow::testing
