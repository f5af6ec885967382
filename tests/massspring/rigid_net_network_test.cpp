// Rigid / net contact end to end through the real `vrflow run` (issue 26, item 4): the rigid
// animator with a gravity force field, the net's animator and the rigid / mass-spring interactor
// run sequentially with them. A 10 kg box dropped 2 m and a small ball reaching the net at about
// 10 m/s are caught by the paper scene's 8 kg net; a bad parameter fails the run.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "process_helpers.hpp"
#include "rigid_harness.hpp"
#include "vrflow/massspring/net.hpp"
#include "vrflow/massspring/solver.hpp"

namespace vrflow::massspring {
namespace {

using testing::TempDir;

// The box (0.3 m, 10 kg) its bottom 2 m above the net; the ball (radius 3 cm, 0.5 kg) thrown
// down at 3 m/s from 5 m over the middle of a cell, so it meets the net at about 9.6 m/s.
const char* kScene = R"({"bodies": [
  {"name": "box", "shape": {"type": "box", "halfExtents": [0.15, 0.15, 0.15]}, "mass": 10,
   "position": [-0.45, 3.1, 0.05], "orientation": [0.0998, 0, 0, 0.995]},
  {"name": "ball", "shape": {"type": "sphere", "radius": 0.03}, "mass": 0.5,
   "position": [0.4, 5.0, 0.0], "linearVelocity": [0, -3, 0]}
]})";

std::string app(const std::string& contactParams) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="rigid-net" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="bodies" package="rigid" type="animator" host="local">
      <param name="scene" value="scene.json"/>
      <param name="sleep" value="false"/>
      <param name="state-file" value="bodies.json"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="field" package="rigid" type="forcefield" host="local">
      <param name="field" value="gravity 0 -9.81 0"/>
    </module>
    <module id="net" package="massspring" type="animator" host="local">
      <param name="mass" value="8"/>
      <param name="stiffness" value="300"/>
      <param name="damping" value="0.2"/>
      <param name="origin" value="0 0.95 0"/>
      <param name="gravity" value="0 -9.81 0"/>
      <param name="state-file" value="net.txt"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="touch" package="massspring" type="rigid" host="local">)" +
         contactParams + R"(</module>
  </modules>
  <connections>
    <connection from="bodies.objects" to="field.objects"/>
    <connection from="bodies.objects" to="touch.objects"/>
    <connection from="net.objects" to="touch.objects"/>
    <connection from="field.forces" to="bodies.events"/>
    <connection from="touch.forces" to="bodies.events"/>
    <connection from="touch.forces" to="net.events"/>
  </connections>
</application>
)";
}

testing::CommandResult run(const TempDir& dir, const std::string& text, int iterations) {
  dir.write("scene.json", kScene);
  const auto file = dir.write("app.xml", text);
  return testing::runCommand({"/bin/sh", "-c",
                              "cd " + dir.path() + " && " + testing::binDir() + "/vrflow run " +
                                  file + " -n " + std::to_string(iterations)},
                             120);
}

TEST(RigidNetNetwork, HeavyBoxAndFastBallAreCaughtByTheNet) {
  TempDir dir;
  // 6 s: the net no longer freezes at its stretch limits (issue 26), so the bodies ride its
  // decaying swing for longer (box 1.4e-1 m/s at 3 s, 5e-3 m/s at 4 s; ball 5e-2 at 4 s).
  const auto result = run(dir, app(""), 600);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto net = loadNet(dir.file("net.txt"));
  ASSERT_TRUE(net) << net.error().message;
  // The rigid animator's final state (nodes/rigid/README.md): bodies with position and velocity.
  const auto state = nlohmann::json::parse(std::ifstream(dir.file("bodies.json")));
  const auto& bodies = state.at("bodies");
  ASSERT_EQ(bodies.size(), 2u);
  EXPECT_LE(maxConstraintRatio(*net), 1 + 1e-9);
  const double halfHeights[2] = {0.15, 0.03};
  for (std::size_t k = 0; k < 2; ++k) {
    const auto p = bodies[k].at("position").get<std::vector<double>>();
    const auto v = bodies[k].at("linearVelocity").get<std::vector<double>>();
    const double surface = surfaceHeight(*net, p[0], p[2]);
    const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    std::printf("%s: centre %.4f m above the net's surface, speed %.2e m/s after 6 s\n",
                k == 0 ? "box" : "ball", p[1] - surface, speed);
    ASSERT_FALSE(std::isnan(surface)) << k << " is no longer over the net";
    EXPECT_GT(p[1] - surface, 0.5 * halfHeights[k]) << k;  // on the net, not through it
    EXPECT_LT(speed, 0.05) << k;
  }
}

TEST(RigidNetNetwork, BadContactParameterFailsTheRunWithTheModulesMessage) {
  TempDir dir;
  const auto result = run(dir, app(R"(<param name="beta" value="2"/>)"), 10);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE(result.err.find("beta"), std::string::npos) << result.err;
}

// The interactor's `gravity` (the field acceleration its solve takes off the rigids' measured
// other forces): a value that is not 3 finite numbers stops the run before any step, with the
// application file's line, the module and the parameter named.
TEST(RigidNetNetwork, BadGravityFailsTheRunNamingTheModuleAndTheParameter) {
  for (const std::string bad : {"0 nan 0", "0 -9.81", "0 1e999 0"}) {
    TempDir dir;
    const auto result = run(dir, app(R"(<param name="gravity" value=")" + bad + R"("/>)"), 10);
    EXPECT_NE(result.exitCode, 0) << bad;
    const std::string out = result.out + result.err;
    EXPECT_NE(out.find("app.xml:"), std::string::npos) << bad << ": " << out;
    EXPECT_NE(out.find("parameter 'gravity' of module 'touch' (massspring/rigid)"),
              std::string::npos)
        << bad << ": " << out;
    EXPECT_FALSE(std::ifstream(dir.file("bodies.json")).good()) << bad << ": nothing ran";
  }
}

}  // namespace
}  // namespace vrflow::massspring
