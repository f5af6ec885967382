// The rigid package's modules through the real `vrflow run`: animator, rigid interactor and force
// field in a cycle (figure 4 of the paper), checked against the same solvers in one process.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "process_helpers.hpp"
#include "vrflow/app/catalog.hpp"
#include "vrflow/rigid/scene.hpp"
#include "vrflow/rigid/world.hpp"

namespace vrflow::testing {
namespace {

// One place for each default: ContactParams' defaults are generated from the interactor's
// manifest, so a library user and the module start from the same values.
TEST(RigidInteractorDefaults, ContactParamsDefaultsAreTheManifests) {
  app::Catalog catalog;
  ASSERT_TRUE(catalog.addPackageFile(sourceDir() + "/nodes/rigid/vrflow-package.xml").ok());
  const app::ModuleType* type = catalog.findModule("rigid", "interactor");
  ASSERT_NE(type, nullptr);
  const auto manifest = app::parameterSet(type->params, {}, "rigid/interactor");
  ASSERT_TRUE(manifest.ok()) << manifest.error().message;
  const rigid::ContactParams defaults;
  EXPECT_EQ(defaults.gravity, manifest->getVec3("gravity"));
  EXPECT_EQ(defaults.restitution, manifest->getFloat("restitution"));
  EXPECT_EQ(defaults.friction, manifest->getFloat("friction"));
  EXPECT_EQ(defaults.restitutionThreshold, manifest->getFloat("restitution-threshold"));
  EXPECT_EQ(defaults.iterations, manifest->getInt("iterations"));
  EXPECT_EQ(defaults.baumgarte, manifest->getFloat("baumgarte"));
  EXPECT_EQ(defaults.slop, manifest->getFloat("slop"));
  EXPECT_FALSE(manifest->firstError().has_value());
}

std::string app(const std::string& scene, const std::string& stateFile) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="rigid-drop" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="bodies" package="rigid" type="animator" host="local">
      <param name="scene" value=")" +
         scene + R"("/>
      <param name="dt" value="0.01"/>
      <param name="state-file" value=")" +
         stateFile + R"("/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="contacts" package="rigid" type="interactor" host="local">
      <param name="gravity" value="0 -9.81 0"/>
    </module>
    <module id="field" package="rigid" type="forcefield" host="local">
      <param name="field" value="gravity 0 -9.81 0"/>
    </module>
  </modules>
  <connections>
    <connection from="bodies.objects" to="field.objects"/>
    <connection from="bodies.objects" to="contacts.objects"/>
    <connection from="field.forces" to="bodies.events"/>
    <connection from="contacts.forces" to="bodies.events"/>
  </connections>
</application>
)";
}

TEST(RigidNetwork, DropSceneComesToRestAndMatchesTheSingleProcessSolvers) {
  TempDir dir;
  const std::string scene = sourceDir() + "/tests/rigid/data/drop.json";
  const auto appFile = dir.file("rigid.xml");
  std::ofstream(appFile) << app(scene, dir.file("state.json"));
  const int iterations = 300;
  const auto result = runCommand({binDir() + "/vrflow", "run", appFile, "-n",
                                  std::to_string(iterations), "--report", dir.file("report.json")},
                                 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto state = nlohmann::json::parse(readFile(dir.file("state.json")));
  EXPECT_EQ(state["steps"].get<int>(), iterations - 1);
  const auto& bodies = state["bodies"];
  ASSERT_EQ(bodies.size(), 4u);

  // The same scene, the same solvers, one process.
  auto loaded = rigid::loadScene(scene);
  ASSERT_TRUE(loaded);
  rigid::RigidWorld world(
      rigid::ForceField({rigid::FieldTerm{rigid::FieldTerm::Kind::Gravity, {0, -9.81, 0}}}), {});
  ASSERT_TRUE(world.add(*loaded));
  for (int i = 0; i < iterations - 1; ++i) world.step(0.01);

  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const auto& b = bodies[i];
    const rigid::Body& mono = world.state().bodies()[i];
    const auto position = b["position"].get<std::vector<double>>();
    const auto velocity = b["linearVelocity"].get<std::vector<double>>();
    const auto low = b["boundsMin"].get<std::vector<double>>();
    // Bit for bit: connections into one port merge in file order, and the app lists the field's
    // before the contacts', the order in which RigidWorld applies them (%.17g round-trips).
    for (int k = 0; k < 3; ++k) EXPECT_EQ(position[k], mono.position[k]) << "body " << i;
    if (b["kinematic"].get<bool>()) {
      EXPECT_EQ(position, (std::vector<double>{0, -0.5, 0}));
      continue;
    }
    // At rest on the ground after 3 s.
    EXPECT_LT(std::hypot(velocity[0], velocity[1], velocity[2]), 0.05) << "body " << i;
    EXPECT_GT(low[1], -0.02) << "body " << i;
    EXPECT_LT(low[1], 0.03) << "body " << i << " should rest on the ground";
  }
  // The ball rolled along x (it was thrown at 0.5 m/s).
  EXPECT_GT(bodies[1]["position"][0].get<double>(), 0.1);
  EXPECT_NEAR(bodies[1]["position"][1].get<double>(), 0.2, 0.01);
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(RigidNetwork, BadSceneFailsTheRunNamingTheFile) {
  TempDir dir;
  const auto scene = dir.file("broken.json");
  std::ofstream(scene)
      << "{\"bodies\": [\n  {\"shape\": {\"type\": \"sphere\"}, \"mass\": 1}\n]}\n";
  const auto appFile = dir.file("rigid.xml");
  std::ofstream(appFile) << app(scene, "");
  const auto result = runCommand({binDir() + "/vrflow", "run", appFile, "-n", "10"}, 60);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE((result.out + result.err).find("broken.json:2: body 0: 'radius' must be a number"),
            std::string::npos)
      << result.out << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

// The force field acts by type: on core point masses when asked to, here with gravity and drag.
TEST(RigidNetwork, ForceFieldMovesPointMassesByType) {
  TempDir dir;
  const auto appFile = dir.write("points.xml", R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="field-points" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="points" package="core" type="points" host="local">
      <param name="count" value="2"/>
      <param name="dt" value="0.01"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="field" package="rigid" type="forcefield" host="local">
      <param name="field" value="gravity 0 -10 0; drag 0.5"/>
      <param name="types" value="point"/>
    </module>
    <module id="recorder" package="core" type="recorder" host="local">
      <param name="file" value=")" + dir.file("points.csv") +
                                                   R"("/>
    </module>
  </modules>
  <connections>
    <connection from="points.objects" to="field.objects"/>
    <connection from="field.forces" to="points.events"/>
    <connection from="points.objects" to="recorder.in"/>
  </connections>
</application>
)");
  const int iterations = 101;
  const auto result =
      runCommand({binDir() + "/vrflow", "run", appFile, "-n", std::to_string(iterations)}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(dir.file("points.csv"));
  ASSERT_EQ(lines.size(), 1u + 2u * iterations);
  // The last line: iteration,source,source_iteration,sim_time,kind,id,x,y,z.
  std::vector<std::string> f;
  std::stringstream in(lines.back());
  for (std::string field; std::getline(in, field, ',');) f.push_back(field);
  ASSERT_GE(f.size(), 9u);
  // The same recursion with m = 1: v += dt (-10 - 0.5 v), y += dt v, for 100 steps.
  double v = 0, y = 0;
  for (int i = 0; i < iterations - 1; ++i) {
    v += 0.01 * (-10 - 0.5 * v);
    y += 0.01 * v;
  }
  EXPECT_NEAR(std::stod(f[7]), y, 1e-4);
  EXPECT_GT(std::stod(f[7]), -10 * 0.5);  // slower than free fall
  EXPECT_TRUE(leftoverProcesses().empty());
}

// A scene that is not a regular file is refused before anything starts, with one error naming
// it: `validate` says so, and `run` neither reads /dev/zero without end nor waits on a FIFO.
TEST(RigidNetwork, SceneThatIsNotARegularFileIsRefusedBeforeTheRun) {
  TempDir dir;
  const auto zeroApp = dir.file("zero.xml");
  std::ofstream(zeroApp) << app("/dev/zero", dir.file("state.json"));
  const auto validated = runCommand({binDir() + "/vrflow", "validate", zeroApp}, 30);
  EXPECT_EQ(validated.exitCode, 1) << validated.err;
  EXPECT_NE(validated.err.find("parameter 'scene' of module 'bodies' (rigid/animator) names "
                               "'/dev/zero', an input that must be a regular file (it is a "
                               "character device, not a regular file)"),
            std::string::npos)
      << validated.err;

  const std::string fifo = dir.file("scene.json");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const auto fifoApp = dir.file("fifo.xml");
  std::ofstream(fifoApp) << app(fifo, dir.file("state.json"));
  const auto ran = runCommand({binDir() + "/vrflow", "run", fifoApp, "-n", "10"}, 30);
  EXPECT_NE(ran.exitCode, 0);
  EXPECT_LT(ran.exitCode, 128) << "killed after 30 s: it waited on the FIFO";
  EXPECT_NE(ran.err.find("names '" + fifo +
                         "', an input that must be a regular file (it is a "
                         "FIFO, not a regular file)"),
            std::string::npos)
      << ran.err;
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

}  // namespace
}  // namespace vrflow::testing
