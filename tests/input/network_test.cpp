// The input package's modules through the real `vrflow run`, with the rigid package: a scripted
// pointer pushes a box, a grab lifts one and lets it fall, the haptic tool at 1 kHz against
// the 100 Hz contacts through the repeat and decimate filters; bad parameters fail the run
// with one error naming the module and the parameter.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string data(const std::string& name) {
  return sourceDir() + "/tests/input/data/" + name;
}

/// The rigid cycle (animator, gravity field, contacts) on `scene` plus `extraModules`, whose
/// connections `extraConnections` add; the animator writes its final state to `state`.
std::string rigidApp(const std::string& scene, const std::string& state,
                     const std::string& extraModules, const std::string& extraConnections,
                     const std::string& gravity = "0 -9.81 0", const std::string& filters = "") {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="input-test" version="1">
  <modules>
    <module id="bodies" package="rigid" type="animator">
      <param name="scene" value=")" +
         scene + R"("/>
      <param name="state-file" value=")" +
         state + R"("/>
      <input port="events" initial-messages="1"/>
    </module>
    <module id="contacts" package="rigid" type="interactor">
      <param name="gravity" value=")" +
         gravity + R"("/>
    </module>
    <module id="field" package="rigid" type="forcefield">
      <param name="field" value="gravity )" +
         gravity + R"("/>
    </module>
)" + extraModules +
         R"(  </modules>
  <filters>)" +
         filters + R"(</filters>
  <connections>
    <connection from="bodies.objects" to="field.objects"/>
    <connection from="bodies.objects" to="contacts.objects"/>
    <connection from="field.forces" to="bodies.events"/>
    <connection from="contacts.forces" to="bodies.events"/>
)" + extraConnections +
         R"(  </connections>
</application>
)";
}

/// The body `index` of the animator's state file.
nlohmann::json body(const std::string& stateFile, std::size_t index) {
  const auto state = nlohmann::json::parse(readFile(stateFile));
  return state["bodies"].at(index);
}

double coordinate(const nlohmann::json& b, int axis) {
  return b["position"][static_cast<std::size_t>(axis)].get<double>();
}

// The pointer is a kinematic sphere (r = 0.1 m) sliding along x at 1 m/s from -1 to 1 at the
// box's mid-height: it meets the box (0.4 m) at x = -0.3 and pushes it ahead, so that when it
// stops at x = 1 the box's centre is at 1 + 0.1 + 0.2 = 1.3, from where friction (0.6 g) lets
// it slide at most v^2 / (2 0.6 g) = 8.5 cm further. It stays upright, on the ground, on the
// path (z = 0).
TEST(InputNetwork, ScriptedPointerPushesABoxAlongItsPath) {
  TempDir dir;
  const auto app = dir.write(
      "push.xml", rigidApp(data("push.json"), dir.file("state.json"),
                           R"(    <module id="pointer" package="input" type="pointer">
      <param name="device" value="script:)" +
                               data("push.keys") + R"("/>
      <param name="radius" value="0.1"/>
    </module>
)",
                           R"(    <connection from="pointer.objects" to="contacts.objects"/>
)"));
  const auto result = runCommand({binDir() + "/vrflow", "run", app, "-n", "300"}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto box = body(dir.file("state.json"), 1);
  EXPECT_GT(coordinate(box, 0), 1.3 - 0.03);
  EXPECT_LT(coordinate(box, 0), 1.3 + 0.085 + 0.03);
  EXPECT_NEAR(coordinate(box, 1), 0.2, 0.01);
  EXPECT_NEAR(coordinate(box, 2), 0.0, 0.02);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

// The grab presses inside the box at 0.1 s, lifts its point 1 m by 1 s and holds it until
// 1.5 s: the box hangs on the spring (200 N/m) at 1.2 - m g / k = 1.151 m. Released, it falls
// back to the ground and comes to rest there.
TEST(InputNetwork, GrabLiftsABodyAndLetsItFall) {
  TempDir dir;
  const std::string grab = R"(    <module id="grab" package="input" type="grab">
      <param name="device" value="script:)" +
                           data("lift.keys") + R"("/>
    </module>
)";
  const std::string connections = R"(    <connection from="bodies.objects" to="grab.objects"/>
    <connection from="grab.forces" to="bodies.events"/>
)";
  const auto app =
      dir.write("lift.xml", rigidApp(data("push.json"), dir.file("state.json"), grab, connections));
  // Iteration i is at time 0.01 i: 151 iterations end at 1.5 s, while held.
  auto held = runCommand({binDir() + "/vrflow", "run", app, "-n", "151"}, 60);
  ASSERT_EQ(held.exitCode, 0) << held.err;
  const auto lifted = body(dir.file("state.json"), 1);
  EXPECT_NEAR(coordinate(lifted, 1), 1.2 - 9.81 / 200.0, 0.03);
  EXPECT_NEAR(coordinate(lifted, 0), 0.0, 0.01);

  auto dropped = runCommand({binDir() + "/vrflow", "run", app, "-n", "400"}, 60);
  ASSERT_EQ(dropped.exitCode, 0) << dropped.err;
  const auto fallen = body(dir.file("state.json"), 1);
  EXPECT_NEAR(coordinate(fallen, 1), 0.2, 0.01);
  const auto v = fallen["linearVelocity"].get<std::vector<double>>();
  EXPECT_LT(std::hypot(v[0], v[1], v[2]), 0.05);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

// The window backend: the grab's `device` port receives a window's pointer events (a scripted
// window standing for the on-screen viewer). A press with the ray on the box picks its front
// face; dragging the ray up lifts the box by that point, releasing drops it.
TEST(InputNetwork, WindowPointerEventsClickAndDragABox) {
  TempDir dir;
  const std::string modules = R"(    <module id="window" package="input-testing" type="clicks">
      <param name="keyframes" value=")" +
                              data("drag.keys") + R"("/>
    </module>
    <module id="grab" package="input" type="grab">
      <param name="device" value="window"/>
    </module>
)";
  const std::string connections = R"(    <connection from="bodies.objects" to="grab.objects"/>
    <connection from="window.events" to="grab.device"/>
    <connection from="grab.forces" to="bodies.events"/>
)";
  const auto app = dir.write(
      "drag.xml", rigidApp(data("push.json"), dir.file("state.json"), modules, connections));
  auto held = runVrflow({"run", app, "-n", "151"}, 60);
  ASSERT_EQ(held.exitCode, 0) << held.err;
  const auto lifted = body(dir.file("state.json"), 1);
  // Hanging by its front face's centre, pulled to y = 1.2 (less the sag, 9.81 / 200 m): the
  // box's top is near that point, its centre about a half side below.
  EXPECT_GT(lifted["boundsMax"][1].get<double>(), 1.2 - 9.81 / 200.0 - 0.05);
  EXPECT_GT(coordinate(lifted, 1), 0.8);
  auto dropped = runVrflow({"run", app, "-n", "400"}, 60);
  ASSERT_EQ(dropped.exitCode, 0) << dropped.err;
  EXPECT_LT(body(dir.file("state.json"), 1)["boundsMin"][1].get<double>(), 0.01);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

std::string hapticModule(const std::string& device, const std::string& log,
                         const std::string& extra = "") {
  return R"(    <module id="tool" package="input" type="haptic">
      <param name="device" value=")" +
         device + R"("/>
      <param name="log" value=")" +
         log + R"("/>
)" + extra +
         R"(      <input port="events" initial-messages="10"/>
    </module>
)";
}

const char* kHapticFilters = R"(
    <filter id="physics_rate" type="decimate"><param name="count" value="10"/></filter>
    <filter id="haptic_rate" type="repeat"><param name="count" value="10"/></filter>
  )";
const char* kHapticConnections = R"(    <connection from="tool.objects" to="physics_rate.in"/>
    <connection from="physics_rate.out" to="contacts.objects"/>
    <connection from="contacts.forces" to="haptic_rate.in"/>
    <connection from="haptic_rate.out" to="tool.events"/>
)";

// The haptic tool at 1 kHz, the contacts at 100 Hz (decimate and repeat filters): the simulated
// hand brings the tool down onto the ground and presses 5 cm into it; over the last 0.2 s the
// force rendered on the hand equals the contact force on the tool. The contacts see the tool
// as a free body (they do not know the coupling's push), so it sinks until Baumgarte's
// correction holds the push: F = m beta (depth - slop) / dt^2, 400 N/m for 0.2 kg.
TEST(InputNetwork, HapticToolAtOneKilohertzPressedOnTheGroundRendersItsReaction) {
  TempDir dir;
  const auto log = dir.file("haptic.csv");
  const auto app = dir.write("haptic.xml", rigidApp(data("ground.json"), dir.file("state.json"),
                                                    hapticModule("arm:" + data("press.keys"), log),
                                                    kHapticConnections, "0 0 0", kHapticFilters));
  const auto result = runCommand({binDir() + "/vrflow", "run", app, "-n", "200"}, 90);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto rows = readCsvRows(log);
  ASSERT_EQ(rows.size(), 2000u);  // one row per tick: 200 physics steps, ten ticks each
  EXPECT_NEAR(std::stod(rows.back()[0]), 2.0, 1e-9);
  double feedback = 0, contact = 0;
  const std::size_t last = 200;
  for (std::size_t i = rows.size() - last; i < rows.size(); ++i) {
    contact += std::stod(rows[i][8]) / last;
    feedback += std::stod(rows[i][11]) / last;
  }
  const double depth = 0.05 - std::stod(rows.back()[5]);  // below one radius up
  EXPECT_NEAR(contact, 0.2 * 0.2 * (depth - 0.005) / (0.01 * 0.01), 0.02 * contact);
  EXPECT_GT(contact, 5.0);
  EXPECT_NEAR(feedback, contact, 0.02 * contact);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

// The head module: a point object at the tracked position every iteration (a scripted head
// walking 1 m along x in 1 s), as the recorder sees it.
TEST(InputNetwork, HeadModuleSendsTheTrackedPositionAsAPointObject) {
  TempDir dir;
  const auto keys = dir.write("walk.keys", "0 0 1.7 2\n1 1 1.7 2\n");
  const auto app = dir.write("head.xml", R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="head" version="1">
  <modules>
    <module id="head" package="input" type="head">
      <param name="device" value="script:)" + keys +
                                             R"("/>
    </module>
    <module id="recorder" package="core" type="recorder">
      <param name="file" value=")" + dir.file("head.csv") +
                                             R"("/>
    </module>
  </modules>
  <connections>
    <connection from="head.objects" to="recorder.in"/>
  </connections>
</application>
)");
  const auto result = runCommand({binDir() + "/vrflow", "run", app, "-n", "51"}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto rows = readCsvRows(dir.file("head.csv"));
  ASSERT_EQ(rows.size(), 51u);
  // iteration,source,source_iteration,sim_time,kind,id,x,y,z: iteration 50 is at 0.5 s.
  ASSERT_GE(rows.back().size(), 9u);
  EXPECT_NEAR(std::stod(rows.back()[3]), 0.5, 1e-12);
  EXPECT_NEAR(std::stod(rows.back()[6]), 0.5, 1e-12);
  EXPECT_NEAR(std::stod(rows.back()[7]), 1.7, 1e-12);
  EXPECT_NEAR(std::stod(rows.back()[8]), 2.0, 1e-12);
  EXPECT_TRUE(leftoverProcesses().empty());
}

// The package's examples, as their README tells a user to run them (outputs moved into a
// temporary folder with --set).
TEST(InputExamples, GrabStackCarriesTheTopBoxAsideAndSetsItDown) {
  TempDir dir;
  const auto result =
      runCommand({binDir() + "/vrflow", "run", sourceDir() + "/nodes/input/examples/grab_stack.xml",
                  "-n", "400", "--set", "bodies.state-file=" + dir.file("state.json")},
                 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto top = body(dir.file("state.json"), 3);
  EXPECT_NEAR(coordinate(top, 0), 1.0, 0.03);
  EXPECT_NEAR(coordinate(top, 1), 0.25, 0.01);
  EXPECT_NEAR(coordinate(top, 2), 0.0, 0.03);
  for (std::size_t i : {1u, 2u}) {  // the two boxes left in the stack did not move
    EXPECT_NEAR(coordinate(body(dir.file("state.json"), i), 0), 0.0, 0.01);
    EXPECT_NEAR(coordinate(body(dir.file("state.json"), i), 1), 0.5 * static_cast<double>(i) - 0.25,
                0.01);
  }
  EXPECT_TRUE(leftoverProcesses().empty());
}

// The haptic probe: while the tool presses on the box, the hand feels the contact force less
// the tool's weight (its gravity is on), and the stroke's friction; the 5 kg box stays put.
TEST(InputExamples, HapticProbeRendersTheBoxsContactLessTheToolsWeight) {
  TempDir dir;
  const auto result = runCommand(
      {binDir() + "/vrflow", "run", sourceDir() + "/nodes/input/examples/haptic_probe.xml", "-n",
       "300", "--set", "bodies.state-file=" + dir.file("state.json"), "--set",
       "tool.log=" + dir.file("haptic.csv")},
      60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto rows = readCsvRows(dir.file("haptic.csv"));
  ASSERT_EQ(rows.size(), 3000u);
  double contact = 0, feedback = 0;
  for (std::size_t i = 1400; i < 1600; ++i) {  // 1.4 s to 1.6 s: pressing
    contact += std::stod(rows[i][8]) / 200;
    feedback += std::stod(rows[i][11]) / 200;
  }
  EXPECT_GT(contact, 5.0);
  EXPECT_NEAR(feedback, contact - 0.2 * 9.81, 0.02 * contact);
  const auto box = body(dir.file("state.json"), 1);
  EXPECT_NEAR(coordinate(box, 0), 0.0, 0.005);
  EXPECT_NEAR(coordinate(box, 1), 0.2, 0.005);
  EXPECT_TRUE(leftoverProcesses().empty());
}

/// Runs `app` and returns its stderr and stdout; expects a failure.
std::string failure(const std::string& app) {
  const auto result = runCommand({binDir() + "/vrflow", "run", app, "-n", "20"}, 60);
  EXPECT_NE(result.exitCode, 0);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
  return result.out + result.err;
}

TEST(InputNetwork, BadDeviceAndParametersFailTheRunWithOneErrorNamingThem) {
  TempDir dir;
  const auto broken = dir.write("broken.keys", "0 0 0 0\n0.5 1 oops 0\n");
  auto pointerApp = [&](const std::string& params) {
    return dir.write(
        "pointer.xml",
        rigidApp(data("push.json"), "", R"(    <module id="pointer" package="input" type="pointer">
)" + params + R"(    </module>
)",
                 R"(    <connection from="pointer.objects" to="contacts.objects"/>
)"));
  };
  auto param = [](const std::string& name, const std::string& value) {
    return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
  };
  const std::vector<std::pair<std::string, std::string>> pointerCases{
      {param("device", "script:" + broken),
       "parameter 'device' of module 'pointer': " + broken + ":2: field 3 is not a finite number"},
      {param("device", "evdev:/dev/input/event-vrflow-missing") + param("hotplug", "false"),
       "parameter 'device' of module 'pointer': evdev:/dev/input/event-vrflow-missing: cannot "
       "open the input device node (No such file or directory; set hotplug to wait for it)"},
      {param("device", "script"),
       "parameter 'keyframes' of module 'pointer': device 'script' needs a keyframe file: set "
       "keyframes"},
      {param("device", "joystick"),
       "parameter 'device' of module 'pointer': device 'joystick': give script:FILE"},
      {param("device", "script:" + data("push.keys")) + param("radius", "-1"), "radius"},
  };
  for (const auto& [params, expected] : pointerCases) {
    const auto text = failure(pointerApp(params));
    EXPECT_NE(text.find(expected), std::string::npos) << text;
  }
  auto hapticApp = [&](const std::string& device, const std::string& extra) {
    return dir.write("haptic.xml",
                     rigidApp(data("ground.json"), "", hapticModule(device, "", extra),
                              kHapticConnections, "0 0 0", kHapticFilters));
  };
  auto text = failure(hapticApp("arm:" + data("press.keys"), param("stiffness", "9000")));
  EXPECT_NE(text.find("parameter 'stiffness' of module 'tool': stiffness 9000 N/m is outside "
                      "the passive range (0, min(2 c / T, 4 m / dt^2)] = (0, 4000]"),
            std::string::npos)
      << text;
  text = failure(hapticApp("script:" + data("press.keys"), ""));
  EXPECT_NE(text.find("parameter 'device' of module 'tool': 'script:" + data("press.keys") +
                      "' renders no force: give arm:FILE or plugin:LIBRARY.so"),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace vrflow::testing
