// A moving concave mesh through the real `vrflow run`: the rigid package's bowl example (a bowl
// standing on the ground catches a ball and a crate), checked against where they must rest and
// against the same solvers in one process; an open mesh fails the run naming file and body.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "process_helpers.hpp"
#include "vrflow/rigid/scene.hpp"
#include "vrflow/rigid/world.hpp"

namespace vrflow::testing {
namespace {

const std::string kExample = "/nodes/rigid/examples/bowl.xml";
const std::string kScene = "/nodes/rigid/examples/bowl.json";

TEST(RigidMeshNetwork, BowlExampleEndsWithTheBallAndCrateInsideTheBowl) {
  TempDir dir;
  const int iterations = 300;
  const auto result = runCommand(
      {binDir() + "/vrflow", "run", sourceDir() + kExample, "-n", std::to_string(iterations),
       "--set", "bodies.state-file=" + dir.file("state.json"), "--report", dir.file("report.json")},
      120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto state = nlohmann::json::parse(readFile(dir.file("state.json")));
  const auto& bodies = state["bodies"];
  ASSERT_EQ(bodies.size(), 4u);  // ground, bowl, ball, crate
  const auto vec = [](const nlohmann::json& j) { return j.get<std::vector<double>>(); };
  const auto bowl = vec(bodies[1]["position"]), bowlLow = vec(bodies[1]["boundsMin"]);
  const auto ball = vec(bodies[2]["position"]), crateLow = vec(bodies[3]["boundsMin"]);
  const auto crateHigh = vec(bodies[3]["boundsMax"]);
  // The bowl (0.6 m wide, 0.3 m high, floor and walls 5 cm) stands on the ground.
  EXPECT_NEAR(bowlLow[1], 0.0, 0.012);
  // The ball (r = 0.08) rests on the bowl's floor, inside its walls, below its rim.
  EXPECT_NEAR(ball[1], 0.05 + 0.08, 0.012);
  EXPECT_LT(std::abs(ball[0] - bowl[0]), 0.25 - 0.08 + 0.01);
  EXPECT_LT(std::abs(ball[2] - bowl[2]), 0.25 - 0.08 + 0.01);
  // The crate too.
  EXPECT_NEAR(crateLow[1], 0.05, 0.015);
  EXPECT_LT(crateHigh[1], 0.3);
  for (std::size_t i = 1; i < 4; ++i) {
    const auto v = vec(bodies[i]["linearVelocity"]);
    EXPECT_LT(std::hypot(v[0], v[1], v[2]), 0.02) << "body " << i;
  }

  // The same scene and solvers in one process give the same bits.
  auto loaded = rigid::loadScene(sourceDir() + kScene);
  ASSERT_TRUE(loaded) << loaded.error().message;
  rigid::RigidWorld world(
      rigid::ForceField({rigid::FieldTerm{rigid::FieldTerm::Kind::Gravity, {0, -9.81, 0}}}), {});
  ASSERT_TRUE(world.add(*loaded));
  for (int i = 0; i < iterations - 1; ++i) world.step(0.01);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const auto position = vec(bodies[i]["position"]);
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_EQ(position[k], world.state().bodies()[i].position[k]) << "body " << i;
  }
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(RigidMeshNetwork, OpenMovingMeshFailsTheRunNamingTheFileAndBody) {
  TempDir dir;
  // The example's bowl without its last triangle.
  auto scene = nlohmann::json::parse(readFile(sourceDir() + kScene));
  scene["bodies"][1]["shape"]["triangles"].erase(scene["bodies"][1]["shape"]["triangles"].size() -
                                                 1);
  const auto broken = dir.write("open.json", scene.dump(1));
  const auto result = runCommand({binDir() + "/vrflow", "run", sourceDir() + kExample, "-n", "10",
                                  "--set", "bodies.scene=" + broken},
                                 60);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_TRUE(std::regex_search(result.out + result.err,
                                std::regex("open\\.json:[0-9]+: body 1 'bowl': dynamic triangle "
                                           "mesh: the mesh is not closed: edge [0-9]+-[0-9]+")))
      << result.out << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
