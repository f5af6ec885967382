#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>  // unsetenv
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../runtime/process_helpers.hpp"

// The fluid module through `vrflow run`: alone, and coupled with a box animator (the test
// package `fluidtest`) in an animator/interactor cycle.
namespace vrflow::testing {
namespace {

std::string fluidModule(const std::string& extra) {
  return R"(    <module id="water" package="fluid" type="fluid" host="local">
      <param name="nx" value="16"/>
      <param name="ny" value="20"/>
      <param name="nz" value="16"/>
      <param name="cell-size" value="0.05"/>
      <param name="fill-max" value="0.8 0.5 0.8"/>
)" + extra +
         "    </module>\n";
}

std::string application(const std::string& modules, const std::string& connections) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="fluid-e2e" version="1">
  <hosts>
    <host id="local" address="127.0.0.1"/>
  </hosts>
  <modules>
)" + modules +
         "  </modules>\n  <connections>\n" + connections + "  </connections>\n</application>\n";
}

std::vector<std::vector<double>> readCsv(const std::string& path, bool header) {
  std::vector<std::vector<double>> rows;
  auto lines = readLines(path);
  for (std::size_t i = header ? 1 : 0; i < lines.size(); ++i) {
    std::vector<double> row;
    std::stringstream in(lines[i]);
    std::string cell;
    while (std::getline(in, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

TEST(FluidModule, RunsAloneAndReportsItsStats) {
  TempDir dir;
  const auto app =
      dir.write("alone.xml", application(fluidModule("      <param name=\"stats\" value=\"" +
                                                     dir.file("stats.csv") + "\"/>\n"),
                                         ""));
  const auto result = runVrflow({"run", app, "--iterations", "40", "--no-progress"}, 120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto rows = readCsv(dir.file("stats.csv"), true);
  ASSERT_EQ(rows.size(), 40u);
  const double volume0 = rows.front()[6];
  for (const auto& row : rows) {
    EXPECT_GT(row[2], 0) << "CG iterations";  // a hydrostatic tank still needs a solve
    EXPECT_LE(row[3], 1e-6) << "CG residual";
    EXPECT_NEAR(row[6], volume0, 0.02 * volume0);  // volume
    EXPECT_LT(row[7], 0.01);                       // a still tank stays still
  }
}

TEST(FluidModule, LightBoxFloatsThroughTheAnimatorInteractorCycle) {
  TempDir dir;
  const std::string box = R"(    <module id="box" package="fluidtest" type="box" host="local">
      <param name="half" value="0.15"/>
      <param name="density" value="500"/>
      <param name="start" value="0.4 0.5 0.4"/>
      <param name="trajectory" value=")" +
                          dir.file("box.csv") + R"("/>
      <input port="events" initial-messages="1"/>
    </module>
)";
  const auto app = dir.write(
      "float.xml", application(fluidModule("      <param name=\"stats\" value=\"" +
                                           dir.file("stats.csv") + "\"/>\n") +
                                   box,
                               "    <connection from=\"box.objects\" to=\"water.objects\"/>\n"
                               "    <connection from=\"water.forces\" to=\"box.events\"/>\n"));
  const auto result = runVrflow({"run", app, "--iterations", "250", "--no-progress"}, 180);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto rows = readCsv(dir.file("box.csv"), false);
  ASSERT_GE(rows.size(), 250u);
  const auto stats = readCsv(dir.file("stats.csv"), true);
  ASSERT_FALSE(stats.empty());
  EXPECT_EQ(stats.back()[8], 1) << "the fluid saw the box";
  EXPECT_GT(stats.back()[5], 0) << "the box covered cells";
  // Water 0.5 m deep, a 0.3 m box of density 500: its bottom settles near 0.5 - 0.15 = 0.35 m
  // (the discretisation floats it up to a cell higher, see the buoyancy test).
  const double y = rows.back()[1], vy = rows.back()[2];
  std::printf("box through vrflow run: y %.3f m, vy %.3f m/s after %zu iterations\n", y, vy,
              rows.size());
  EXPECT_GT(y - 0.15, 0.25);
  EXPECT_LT(y - 0.15, 0.45);
  EXPECT_LT(std::abs(vy), 0.15);
}

// An mpirun for VRFLOW_MPIRUN in `dir`: it appends its arguments to dir/mpirun.log and runs the
// real mpirun.
std::string loggingMpirun(const TempDir& dir) {
  const auto wrapper = dir.write(
      "mpirun", "#!/bin/sh\necho \"$@\" >> '" + dir.file("mpirun.log") + "'\nexec mpirun \"$@\"\n");
  EXPECT_EQ(chmod(wrapper.c_str(), 0755), 0);
  return wrapper;
}

// The test box animator in the default tank, its trajectory written to `trajectory`, first in
// the fluid's cycle (one initial message on its events).
std::string cycleBox(const std::string& trajectory) {
  return R"(    <module id="box" package="fluidtest" type="box" host="local">
      <param name="trajectory" value=")" +
         trajectory + R"("/>
      <input port="events" initial-messages="1"/>
    </module>
)";
}

// Two blocks, started by vrflow through mpirun (the manifest's mpi-ranks="blocks"; VRFLOW_MPIRUN
// names a wrapper that logs its arguments and runs the real mpirun): the box must follow the same
// path as with one block. The blocks differ in the last bits (block-Jacobi preconditioner, sums
// at block borders), and a particle that crosses a cell border in one run and not the other
// changes the cell classification discretely, so the paths drift apart slowly: the stated
// tolerance is 1e-3 m (2 % of a cell) after 100 iterations.
TEST(FluidModule, TwoBlocksThroughMpirunFollowTheSerialPath) {
  TempDir wrapperDir;
  const auto log = wrapperDir.file("mpirun.log");
  const auto wrapper = loggingMpirun(wrapperDir);
  std::vector<double> finalY;
  double travel = 0.0;  // of the serial box, from its start at y = 0.5
  for (const int blocks : {1, 2}) {
    setenv("VRFLOW_MPIRUN", wrapper.c_str(), 1);
    TempDir dir;
    const std::string box = cycleBox(dir.file("box.csv"));
    const auto app = dir.write(
        "blocks.xml", application(fluidModule("      <param name=\"blocks\" value=\"" +
                                              std::to_string(blocks) + "\"/>\n") +
                                      box,
                                  "    <connection from=\"box.objects\" to=\"water.objects\"/>\n"
                                  "    <connection from=\"water.forces\" to=\"box.events\"/>\n"));
    const auto result = runVrflow({"run", app, "--iterations", "100", "--no-progress"}, 180);
    unsetenv("VRFLOW_MPIRUN");
    ASSERT_EQ(result.exitCode, 0) << blocks << " blocks: " << result.err;
    // A module left hanging in MPI_Finalize by its blocks does not fail the run: vrflow stops it
    // after the last iteration with this warning.
    EXPECT_EQ(result.err.find("did not exit"), std::string::npos) << blocks << ": " << result.err;
    const auto rows = readCsv(dir.file("box.csv"), false);
    ASSERT_GE(rows.size(), 100u);
    finalY.push_back(rows[99][1]);
    for (std::size_t i = 0; i < 100 && blocks == 1; ++i) {
      travel = std::max(travel, std::abs(rows[i][1] - 0.5));
    }
    const auto left = leftoverProcesses();  // mpirun and its ranks are gone with the run
    EXPECT_TRUE(left.empty()) << blocks << " blocks: " << left.front();
  }
  // The wrapper ran once: for 2 blocks only, with 2 ranks of the fluid module.
  const auto calls = readLines(log);
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_NE(calls[0].find("-np 2"), std::string::npos) << calls[0];
  EXPECT_NE(calls[0].find("vrflow-fluid"), std::string::npos) << calls[0];
  std::printf("box y after 100 iterations: 1 block %.9f, 2 blocks %.9f; largest travel %.4f m\n",
              finalY[0], finalY[1], travel);
  EXPECT_NEAR(finalY[1], finalY[0], 1e-3);
  // It moved (1.3 cm at most, from the water it displaced at the start; the step-100 value is
  // one phase of its bobbing): the comparison is not of a box at rest.
  EXPECT_GT(travel, 0.005);
}

// Only mpirun starts the ranks of a module (the runtime starts every process): with
// VRFLOW_MPIRUN=none a fluid of 2 blocks is refused before anything starts (the box, first in
// the file, never writes its trajectory), with one error naming the module and its parameter.
TEST(FluidModule, WithoutMpirunTwoBlocksAreRefusedBeforeAnythingStarts) {
  TempDir dir;
  const auto app = dir.write(
      "none.xml", application(cycleBox(dir.file("box.csv")) +
                                  fluidModule("      <param name=\"blocks\" value=\"2\"/>\n"),
                              "    <connection from=\"box.objects\" to=\"water.objects\"/>\n"
                              "    <connection from=\"water.forces\" to=\"box.events\"/>\n"));
  setenv("VRFLOW_MPIRUN", "none", 1);
  const auto result = runVrflow({"run", app, "--iterations", "5", "--no-progress"}, 60);
  unsetenv("VRFLOW_MPIRUN");
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("module 'water' (host local) cannot start: VRFLOW_MPIRUN=none, but "
                            "its 'blocks' = 2 makes it 2 MPI ranks of one mpirun (unset "
                            "VRFLOW_MPIRUN, or set 'blocks' to 1)"),
            std::string::npos)
      << result.err;
  EXPECT_FALSE(std::ifstream(dir.file("box.csv")).good()) << "the box was started";
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << left.front();
  const auto shm = vrflowShmEntries();
  EXPECT_TRUE(shm.empty()) << shm.front();
}

// Under `vrflow launch` the daemon of the module's host starts its ranks: the box animator on
// host a, the fluid as 2 ranks on host b (127.0.0.2), coupled across the TCP link; the box
// follows the serial path as on one host, and host b's daemon ran mpirun.
TEST(FluidModule, TwoBlocksOnAnotherHostAreStartedByThatHostsDaemon) {
  TempDir dir;
  const auto log = dir.file("mpirun.log");
  const auto wrapper = loggingMpirun(dir);
  std::string app = application(
      fluidModule("      <param name=\"blocks\" value=\"2\"/>\n") + cycleBox(dir.file("box.csv")),
      "    <connection from=\"box.objects\" to=\"water.objects\"/>\n"
      "    <connection from=\"water.forces\" to=\"box.events\"/>\n");
  app.replace(app.find("  </hosts>"), 0, "    <host id=\"b\" address=\"127.0.0.2\"/>\n");
  const std::string onLocal = "type=\"fluid\" host=\"local\"";
  app.replace(app.find(onLocal), onLocal.size(), "type=\"fluid\" host=\"b\"");
  setenv("VRFLOW_MPIRUN", wrapper.c_str(), 1);
  const auto result = runVrflow(
      {"launch", dir.write("hosts.xml", app), "--backend", "local", "--iterations", "100"}, 180);
  unsetenv("VRFLOW_MPIRUN");
  ASSERT_EQ(result.exitCode, 0) << result.out << result.err;
  const auto rows = readCsv(dir.file("box.csv"), false);
  ASSERT_GE(rows.size(), 100u);
  // The serial value of TwoBlocksThroughMpirunFollowTheSerialPath (same tank and box).
  EXPECT_NEAR(rows[99][1], 0.50901, 1e-3);
  const auto calls = readLines(log);
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_NE(calls[0].find("-np 2"), std::string::npos) << calls[0];
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << left.front();
}

// A module of several ranks whose launcher cannot be run: one clear error, nothing left behind.
TEST(FluidModule, MissingMpirunIsAClearError) {
  TempDir dir;
  setenv("VRFLOW_MPIRUN", "/nonexistent/mpirun", 1);
  const auto app = dir.write(
      "blocks.xml", application(fluidModule("      <param name=\"blocks\" value=\"2\"/>\n"), ""));
  const auto result = runVrflow({"run", app, "--iterations", "5", "--no-progress"}, 60);
  unsetenv("VRFLOW_MPIRUN");
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE(result.err.find("mpirun"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("water"), std::string::npos) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

// With the rigid package's own animator and gravity field: a 0.3 m box of density 500 floats
// (free to turn: a cube of half the water's density tips onto an edge, so only its height is
// checked: between half under water and resting on the surface, not sunk, not flying).
TEST(FluidModule, BoxOfTheRigidPackageFloats) {
  TempDir dir;
  const auto scene = dir.write("scene.json", R"({
  "bodies": [
    {"name": "float", "shape": {"type": "box", "halfExtents": [0.15, 0.15, 0.15]}, "density": 500,
     "position": [0.4, 0.5, 0.4]}
  ]
}
)");
  const std::string rigid = R"(    <module id="bodies" package="rigid" type="animator" host="local">
      <param name="scene" value=")" +
                            scene + R"("/>
      <param name="state-file" value=")" +
                            dir.file("state.json") + R"("/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="gravity" package="rigid" type="forcefield" host="local"/>
)";
  const auto app = dir.write(
      "rigid.xml", application(fluidModule("") + rigid,
                               "    <connection from=\"bodies.objects\" to=\"water.objects\"/>\n"
                               "    <connection from=\"bodies.objects\" to=\"gravity.objects\"/>\n"
                               "    <connection from=\"water.forces\" to=\"bodies.events\"/>\n"
                               "    <connection from=\"gravity.forces\" to=\"bodies.events\"/>\n"));
  const auto result = runVrflow({"run", app, "--iterations", "250", "--no-progress"}, 180);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto state = nlohmann::json::parse(readFile(dir.file("state.json")));
  ASSERT_EQ(state["bodies"].size(), 1u);
  const double y = state["bodies"][0]["position"][1].get<double>();
  const double vy = state["bodies"][0]["linearVelocity"][1].get<double>();
  std::printf("rigid-package box after 250 iterations: y %.3f m, vy %.3f m/s\n", y, vy);
  EXPECT_GT(y, 0.42);  // the water is 0.5 m deep: sunk would be 0.15 to 0.26
  EXPECT_LT(y, 0.66);  // resting on the surface at most
  EXPECT_LT(std::abs(vy), 0.2);
}

// particle-regions 2 1 1: the particles leave as two fluid objects, the halves x < 0.4 m and
// x >= 0.4 m of the grid, each with its own particles and their bounds, so that a route filter
// sends the tile-viewer that sees only x <= 0.3 m the left half, every iteration, and the one
// that sees everything both halves, which together hold every particle. A viewer's volume
// reaches the route only after its first message (`route` does not wait for it), so the first
// iterations may reach a viewer empty; one-message connections keep that lag to a few
// iterations whatever the machine's load.
TEST(FluidModule, ParticleRegionsLetARouteFilterSendEachViewerOnlyWhatItSees) {
  TempDir dir;
  std::string modules = fluidModule("      <param name=\"particle-regions\" value=\"2 1 1\"/>\n");
  const char* boxes[] = {"0 -1 -1 0.3 2 2", "all"};
  std::string connections =
      "    <connection from=\"water.fluid\" to=\"wall.in\" capacity=\"1\"/>\n";
  for (int k = 0; k < 2; ++k) {
    const std::string id = "v" + std::to_string(k);
    modules += "    <module id=\"" + id +
               "\" package=\"routing\" type=\"tile-viewer\" host=\"local\">\n" +
               "      <param name=\"box\" value=\"" + boxes[k] + "\"/>\n" +
               "      <param name=\"file\" value=\"" + dir.file(id + ".csv") + "\"/>\n" +
               "    </module>\n";
    connections += "    <connection from=\"wall.out" + std::to_string(k) + "\" to=\"" + id +
                   ".objects\" capacity=\"1\"/>\n    <connection from=\"" + id +
                   ".interest\" to=\"wall.interest" + std::to_string(k) + "\"/>\n";
  }
  std::string app = application(modules, connections);
  app.replace(app.find("  <connections>"), 0,
              "  <filters>\n    <filter id=\"wall\" type=\"route\" host=\"local\">\n"
              "      <param name=\"outputs\" value=\"2\"/>\n    </filter>\n  </filters>\n");
  const auto result =
      runVrflow({"--packages", binDir() + "/../share/vrflow/example-packages", "run",
                 dir.write("regions.xml", app), "--iterations", "40", "--no-progress"},
                120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  // iteration -> resource id -> vertex count, from iteration,kind,id,op,mask,x,ref lines
  const auto meshes = [](const std::vector<std::string>& lines) {
    std::map<long, std::map<std::string, long>> out;
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<std::string> f;
      std::stringstream in(lines[i]);
      std::string cell;
      while (std::getline(in, cell, ',')) f.push_back(cell);
      if (f.size() >= 5 && f[1] == "resource") out[std::stol(f[0])][f[2]] = std::stol(f[4]);
    }
    return out;
  };
  const auto left = meshes(readLines(dir.file("v0.csv")));
  const auto all = meshes(readLines(dir.file("v1.csv")));
  ASSERT_GE(all.size(), 30u);
  ASSERT_GE(left.size(), 30u);
  long total = -1;
  for (const auto& [it, regions] : all) {
    if (left.find(it) == left.end() && it < 10) continue;  // before the left tile's volume
    ASSERT_EQ(regions.size(), 2u) << "both halves, iteration " << it;
    long sum = 0;
    for (const auto& [id, count] : regions) {
      EXPECT_GT(count, 0) << "the tank is full across x";
      sum += count;
    }
    if (total < 0) total = sum;
    EXPECT_EQ(sum, total) << "every particle in one half or the other, iteration " << it;
    const auto mine = left.find(it);
    ASSERT_NE(mine, left.end()) << "the left tile's half, iteration " << it;
    ASSERT_EQ(mine->second.size(), 1u) << "only the left half, iteration " << it;
    const auto& [id, count] = *mine->second.begin();
    ASSERT_EQ(regions.count(id), 1u);
    EXPECT_EQ(count, regions.at(id)) << "iteration " << it;
    EXPECT_LT(count, sum);
  }
  EXPECT_GT(total, 1000);
}

TEST(FluidModule, ParticleRegionsBeyondTheGridAreRefused) {
  TempDir dir;
  const auto app = dir.write(
      "regions.xml",
      application(fluidModule("      <param name=\"particle-regions\" value=\"17 1 1\"/>\n"), ""));
  const auto result = runVrflow({"run", app, "--iterations", "3", "--no-progress"}, 60);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE(result.err.find("particle-regions"), std::string::npos) << result.err;
}

TEST(FluidModule, AbsurdTimeStepStopsTheRunWithTheSolversMessage) {
  TempDir dir;
  const auto app = dir.write(
      "bad.xml", application(fluidModule("      <param name=\"dt\" value=\"0.9\"/>\n"), ""));
  const auto result = runVrflow({"run", app, "--iterations", "5", "--no-progress"}, 60);
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE((result.out + result.err).find("time step"), std::string::npos) << result.err;
}

TEST(FluidModule, ZeroGridSizeIsRejectedByValidation) {
  TempDir dir;
  const auto app = dir.write(
      "zero.xml", application(fluidModule("      <param name=\"ny\" value=\"0\"/>\n"), ""));
  const auto result = runVrflow({"validate", app}, 60);
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE((result.out + result.err).find("ny"), std::string::npos) << result.out << result.err;
}

TEST(FluidModule, ThreadsOutOfRangeAreRejectedByValidation) {
  TempDir dir;
  for (const char* threads : {"65", "-1"}) {
    const auto app = dir.write(
        "threads.xml",
        application(
            fluidModule(std::string("      <param name=\"threads\" value=\"") + threads + "\"/>\n"),
            ""));
    const auto result = runVrflow({"validate", app}, 60);
    EXPECT_EQ(result.exitCode, 1) << threads;
    EXPECT_NE((result.out + result.err).find("threads"), std::string::npos)
        << result.out << result.err;
  }
}

TEST(FluidModule, UnknownPreconditionerIsRejectedByValidation) {
  TempDir dir;
  const auto app = dir.write(
      "preconditioner.xml",
      application(fluidModule("      <param name=\"preconditioner\" value=\"jacobi\"/>\n"), ""));
  const auto result = runVrflow({"validate", app}, 60);
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE((result.out + result.err).find("preconditioner"), std::string::npos)
      << result.out << result.err;
}

// The module's threads change no bit: the test box in the tank's cycle; its trajectory and the
// fluid's final state (particle centroid and bounds, the box's last force) with 1 and 3 threads
// are the same text.
TEST(FluidModule, ThreeThreadsGiveTheSameRunAsOne) {
  TempDir dir;
  std::string outputs[2];
  const char* threads[2] = {"1", "3"};
  for (int run = 0; run < 2; ++run) {
    const std::string state = dir.file(std::string("state-") + threads[run] + ".json");
    const std::string path = dir.file(std::string("box-") + threads[run] + ".csv");
    const auto app = dir.write(
        "threads.xml",
        application(
            fluidModule(std::string("      <param name=\"threads\" value=\"") + threads[run] +
                        "\"/>\n      <param name=\"state-file\" value=\"" + state + "\"/>\n") +
                cycleBox(path),
            "    <connection from=\"box.objects\" to=\"water.objects\"/>\n"
            "    <connection from=\"water.forces\" to=\"box.events\"/>\n"));
    const auto result = runVrflow({"run", app, "--iterations", "40", "--no-progress"}, 120);
    ASSERT_EQ(result.exitCode, 0) << result.err;
    for (const auto& file : {state, path}) {
      for (const auto& line : readLines(file)) outputs[run] += line + "\n";
    }
  }
  EXPECT_GT(outputs[0].size(), 1000u);
  EXPECT_EQ(outputs[1], outputs[0]);
}

}  // namespace
}  // namespace vrflow::testing
