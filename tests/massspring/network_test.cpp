// The modules end to end through the real `vrflow run`.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>

#include "process_helpers.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/solver.hpp"

namespace vrflow::massspring {
namespace {

using testing::TempDir;

testing::CommandResult run(const TempDir& dir, const std::string& app, int iterations) {
  const auto file = dir.write("app.xml", app);
  return testing::runCommand(
      {"/bin/sh", "-c",
       "cd " + dir.path() + " && " + testing::binDir() + "/vrflow run " + file + " -n " +
           std::to_string(iterations) + " --report " + dir.file("report.json")},
      90);
}

const char* kHeader = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="massspring-test" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
)";

// The paper's split: springs from the spring interactor once per outer step, gravity in the
// animator, one initial message on the animator's event port. The network's final state must be
// bit for bit what the same library calls give in one process.
TEST(MassSpringNetwork, AnimatorAndSpringInteractorMatchTheLibraryInOneProcess) {
  TempDir dir;
  const std::string app = std::string(kHeader) + R"(  <modules>
    <module id="net" package="massspring" type="animator" host="local">
      <param name="n" value="6"/>
      <param name="m" value="5"/>
      <param name="spacing" value="0.2"/>
      <param name="mass" value="0.6"/>
      <param name="stiffness" value="200"/>
      <param name="damping" value="0.1"/>
      <param name="max-stretch" value="1.05"/>
      <param name="origin" value="0 1 0"/>
      <param name="dt" value="0.01"/>
      <param name="substeps" value="4"/>
      <param name="internal-springs" value="false"/>
      <param name="gravity" value="0 -9.81 0"/>
      <param name="state-file" value="final.net"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="springs" package="massspring" type="spring" host="local"/>
  </modules>
  <connections>
    <connection from="net.objects" to="springs.objects"/>
    <connection from="springs.forces" to="net.events"/>
  </connections>
</application>
)";
  const int iterations = 120;
  const auto result = run(dir, app, iterations);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  auto final = loadNet(dir.file("final.net"));
  ASSERT_TRUE(final) << final.error().message;

  GridParams grid;
  grid.n = 6;
  grid.m = 5;
  grid.spacing = 0.2;
  grid.mass = 0.6;
  grid.stiffness = 200;
  grid.damping = 0.1;
  grid.maxStretch = 1.05;
  grid.origin = {0, 1, 0};
  auto net = generateGrid(grid);
  ASSERT_TRUE(net);
  StepOptions options;
  options.dt = 0.01;
  options.substeps = 4;
  options.internalSprings = false;
  options.gravity = {0, -9.81, 0};
  // Iteration 0 sends the initial state; iterations 1..N-1 each step once with the spring
  // forces of the state sent one iteration before.
  std::vector<double> forces(3 * net->nodeCount());
  for (int i = 1; i < iterations; ++i) {
    std::fill(forces.begin(), forces.end(), 0.0);
    addSpringForces(*net, forces);
    step(*net, forces, options);
  }
  EXPECT_TRUE(*final == *net) << "network and one-process results differ";
  // And the physics: corners where they were, the middle sagging below them.
  EXPECT_EQ(final->positions[1], 1.0);
  EXPECT_LT(final->positions[3 * 14 + 1], 0.995);
  EXPECT_LE(maxConstraintRatio(*final), 1 + 1e-9);
}

// Two animators (internal springs, sub-steps), the collision interactor and the rigid / mass-
// spring interactor (no rigids here: it must run and send nothing harmful): the upper net lands
// on the lower one and stays above it.
TEST(MassSpringNetwork, CollisionInteractorKeepsTwoNetsApart) {
  TempDir dir;
  const std::string app = std::string(kHeader) + R"(  <modules>
    <module id="lower" package="massspring" type="animator" host="local">
      <param name="n" value="10"/>
      <param name="m" value="10"/>
      <param name="spacing" value="0.1"/>
      <param name="stiffness" value="400"/>
      <param name="gravity" value="0 -9.81 0"/>
      <param name="state-file" value="lower.net"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="upper" package="massspring" type="animator" host="local">
      <param name="n" value="6"/>
      <param name="m" value="6"/>
      <param name="spacing" value="0.1"/>
      <param name="stiffness" value="400"/>
      <param name="pin-corners" value="false"/>
      <param name="origin" value="0.05 0.3 0.05"/>
      <param name="gravity" value="0 -9.81 0"/>
      <param name="state-file" value="upper.net"/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="collide" package="massspring" type="collision" host="local"/>
    <module id="touch" package="massspring" type="rigid" host="local"/>
  </modules>
  <connections>
    <connection from="lower.objects" to="collide.objects"/>
    <connection from="upper.objects" to="collide.objects"/>
    <connection from="lower.objects" to="touch.objects"/>
    <connection from="upper.objects" to="touch.objects"/>
    <connection from="collide.forces" to="lower.events"/>
    <connection from="collide.forces" to="upper.events"/>
    <connection from="touch.forces" to="lower.events"/>
    <connection from="touch.forces" to="upper.events"/>
  </connections>
</application>
)";
  const auto result = run(dir, app, 150);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  auto lower = loadNet(dir.file("lower.net"));
  auto upper = loadNet(dir.file("upper.net"));
  ASSERT_TRUE(lower) << lower.error().message;
  ASSERT_TRUE(upper) << upper.error().message;
  // It fell onto the lower net (which sagged), and every upper node is on the +y side of it.
  EXPECT_LT(upper->positions[1], 0.2);
  int below = 0;
  for (std::size_t i = 0; i < upper->nodeCount(); ++i) {
    const auto x = upper->position(i);
    double best = 1e300, side = 1;
    for (std::size_t t = 0; t < lower->surface.size(); t += 3) {
      const auto a = lower->position(lower->surface[t]), b = lower->position(lower->surface[t + 1]),
                 c = lower->position(lower->surface[t + 2]);
      const auto cp = closestPointOnTriangle(x, a, b, c);
      const msg::Vec3 d{x[0] - cp.point[0], x[1] - cp.point[1], x[2] - cp.point[2]};
      const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (dist >= best) continue;
      best = dist;
      const msg::Vec3 e1{b[0] - a[0], b[1] - a[1], b[2] - a[2]},
          e2{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      side = d[0] * (e1[1] * e2[2] - e1[2] * e2[1]) + d[1] * (e1[2] * e2[0] - e1[0] * e2[2]) +
             d[2] * (e1[0] * e2[1] - e1[1] * e2[0]);
    }
    if (side < 0) ++below;
  }
  EXPECT_EQ(below, 0);
}

TEST(MassSpringNetwork, MissingNetFileFailsTheRunWithAClearMessage) {
  TempDir dir;
  const std::string app = std::string(kHeader) + R"(  <modules>
    <module id="net" package="massspring" type="animator" host="local">
      <param name="file" value="no-such.net"/>
    </module>
  </modules>
  <connections/>
</application>
)";
  const auto result = run(dir, app, 10);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE((result.out + result.err)
                .find("names 'no-such.net', an input that must be a regular file (No such file or "
                      "directory)"),
            std::string::npos)
      << result.out << result.err;
}

TEST(MassSpringNetwork, BadParameterFailsTheRunWithAClearMessage) {
  TempDir dir;
  const std::string app = std::string(kHeader) + R"(  <modules>
    <module id="net" package="massspring" type="animator" host="local">
      <param name="orientation" value="0 0 1"/>
    </module>
  </modules>
  <connections/>
</application>
)";
  const auto result = run(dir, app, 10);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_NE(
      (result.out + result.err).find("parameter 'orientation' = '0 0 1' must be 4 finite numbers"),
      std::string::npos)
      << result.out << result.err;
}

// A net file that is not a regular file is refused before anything starts, naming it: `validate`
// says so for /dev/zero, and `run` does not wait on a FIFO.
TEST(MassSpringNetwork, NetFileThatIsNotARegularFileIsRefusedBeforeTheRun) {
  TempDir dir;
  const auto appWith = [](const std::string& file) {
    return std::string(kHeader) + R"(  <modules>
    <module id="net" package="massspring" type="animator" host="local">
      <param name="file" value=")" +
           file + R"("/>
    </module>
  </modules>
  <connections/>
</application>
)";
  };
  const auto zeroApp = dir.write("zero.xml", appWith("/dev/zero"));
  const auto validated =
      testing::runCommand({testing::binDir() + "/vrflow", "validate", zeroApp}, 30);
  EXPECT_EQ(validated.exitCode, 1) << validated.err;
  EXPECT_NE(validated.err.find("parameter 'file' of module 'net' (massspring/animator) names "
                               "'/dev/zero', an input that must be a regular file (it is a "
                               "character device, not a regular file)"),
            std::string::npos)
      << validated.err;

  const std::string fifo = dir.file("net.txt");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const auto ran = run(dir, appWith(fifo), 10);
  EXPECT_NE(ran.exitCode, 0);
  EXPECT_LT(ran.exitCode, 128) << "killed at the timeout: it waited on the FIFO";
  EXPECT_NE(ran.err.find("names '" + fifo +
                         "', an input that must be a regular file (it is a "
                         "FIFO, not a regular file)"),
            std::string::npos)
      << ran.err;
}

// The animator warns once, naming the module and the numbers, when its net's springs are
// integrated explicitly beyond omega h < 2: the paper scene's net (20 x 20, 8 kg, 300 N/m) with
// springs from the interactor once per 10 ms step (omega dt 2.99), or in too few sub-steps; not
// in 3 sub-steps (omega h 1.0).
TEST(MassSpringNetwork, AnimatorWarnsOnceWhenItsExplicitSpringsAreBeyondTheirStabilityLimit) {
  auto app = [](const std::string& internal, int substeps) {
    return std::string(kHeader) + R"(  <modules>
    <module id="hammock" package="massspring" type="animator" host="local">
      <param name="mass" value="8"/>
      <param name="stiffness" value="300"/>
      <param name="damping" value="0.2"/>
      <param name="substeps" value=")" +
           std::to_string(substeps) + R"("/>
      <param name="internal-springs" value=")" +
           internal + R"("/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="springs" package="massspring" type="spring" host="local"/>
  </modules>
  <connections>
    <connection from="hammock.objects" to="springs.objects"/>
    <connection from="springs.forces" to="hammock.events"/>
  </connections>
</application>
)";
  };
  auto count = [](const std::string& text, const std::string& what) {
    int n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  TempDir external, few, enough;
  const auto once = run(external, app("false", 1), 5);
  ASSERT_EQ(once.exitCode, 0) << once.err;
  EXPECT_EQ(count(once.err, "module 'hammock': its springs come from an interactor"), 1)
      << once.err;
  EXPECT_NE(once.err.find("omega*h 2.99 with h 0.01 s"), std::string::npos) << once.err;
  EXPECT_NE(once.err.find("substeps >= 2"), std::string::npos) << once.err;
  // Internal springs: h = dt / substeps. (The interactor's forces then count twice: this run only
  // looks at the warning.)
  const auto one = run(few, app("true", 1), 5);
  ASSERT_EQ(one.exitCode, 0) << one.err;
  EXPECT_EQ(count(one.err, "module 'hammock': the net's fastest spring mode"), 1) << one.err;
  EXPECT_NE(one.err.find("use substeps >= 2"), std::string::npos) << one.err;
  const auto three = run(enough, app("true", 3), 5);
  ASSERT_EQ(three.exitCode, 0) << three.err;
  EXPECT_EQ(three.err.find("explicit limit"), std::string::npos) << three.err;
}

}  // namespace
}  // namespace vrflow::massspring
