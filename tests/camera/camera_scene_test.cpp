// examples/camera_user (issue 21, item 8) through the real `vrflow run` and `vrflow launch`, at
// a CI size: the user filmed by 5 synthetic cameras pushes the box off the ledge, presses the
// net and sweeps a hand through it and the water; one host and three loopback hosts (127.0.51.1-3)
// give the same digest for every output, and two runs the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "process_helpers.hpp"
#include "user_scenes.hpp"
#include "vrflow/camera/synthetic_user.hpp"

namespace vrflow::testing {
namespace {

// The hand is at its lowest, pressing the net, at 1.8 to 2.0 s (dt 0.01); it then sweeps along
// -z until 3 s.
constexpr int kIterations = 200;

// The CI size: a coarser hull and fluid than the example's.
const std::vector<std::string> kSmall = {
    "--set", "hull.cells=40", "--set", "water.nx=16",           "--set", "water.ny=24",
    "--set", "water.nz=16",   "--set", "water.cell-size=0.125", "--set", "view.every=100"};

std::string example(const std::string& file) {
  return sourceDir() + "/examples/camera_user/" + file;
}

// Runs `vrflow ARGS` in `folder` (created); fails the test when it does not exit 0.
void vrflowIn(const std::string& folder, std::vector<std::string> args) {
  std::filesystem::create_directories(folder);
  std::string command = "cd '" + folder + "' && exec '" + binDir() + "/vrflow'";
  for (const auto& arg : args) command += " '" + arg + "'";
  const auto result = runCommand({"/bin/sh", "-c", command}, 900);
  ASSERT_EQ(result.exitCode, 0) << command << "\n" << result.out << result.err;
}

std::vector<std::string> withSmall(std::vector<std::string> args) {
  args.insert(args.end(), kSmall.begin(), kSmall.end());
  return args;
}

// The outputs' digests and message counts of a report, by "module.port".
std::map<std::string, std::string> outputs(const std::string& report) {
  const auto json = nlohmann::json::parse(readFile(report));
  std::map<std::string, std::string> byPort;
  for (const auto& output : json["outputs"]) {
    byPort[output["module"].get<std::string>() + "." + output["port"].get<std::string>()] =
        output["last_digest"].dump() + " after " + output["messages"].dump();
  }
  return byPort;
}

// The lowest node of a net file within `radius` of (x, z) in the horizontal plane.
double lowestNear(const std::vector<msg::Vec3>& net, double x, double z, double radius) {
  double lowest = 1e9;
  for (const auto& p : net) {
    if (std::hypot(p[0] - x, p[2] - z) < radius) lowest = std::min(lowest, p[1]);
  }
  return lowest;
}

TEST(CameraUserScene, OneHostAndThreeHostsAgreeAndTheUserPushesTheBoxOffTheLedgeAndPressesTheNet) {
  TempDir dir;
  const std::string n = std::to_string(kIterations);
  vrflowIn(dir.file("one"), withSmall({"run", example("camera_user.xml"), "-n", n, "--no-progress",
                                       "--report", "report.json"}));
  vrflowIn(dir.file("again"), withSmall({"run", example("camera_user.xml"), "-n", n,
                                         "--no-progress", "--report", "report.json"}));
  vrflowIn(dir.file("three"), withSmall({"launch", example("camera_user_3hosts.xml"), "--hosts",
                                         example("camera_user.hosts"), "-n", n, "--no-progress",
                                         "--report", "report.json"}));

  // Every output: the same digest after the same number of messages, in all three runs.
  const auto one = outputs(dir.file("one/report.json"));
  EXPECT_GE(one.size(), 20u);
  EXPECT_EQ(one, outputs(dir.file("again/report.json")));
  EXPECT_EQ(one, outputs(dir.file("three/report.json")));
  for (const char* file : {"bodies-final.json", "net-final.txt", "fluid-final.json"}) {
    const std::string state = readFile(dir.file(std::string("one/") + file));
    EXPECT_FALSE(state.empty()) << file;
    EXPECT_EQ(state, readFile(dir.file(std::string("again/") + file))) << file;
    EXPECT_EQ(state, readFile(dir.file(std::string("three/") + file))) << file;
  }

  // The box (the last body) started on the ledge (x 0.30 to 0.62, top at 1.40 m) at x 0.38:
  // the hand pushed it along +x past the ledge's edge and it fell below the ledge's top.
  const auto bodies = nlohmann::json::parse(readFile(dir.file("one/bodies-final.json")));
  const auto box = bodies["bodies"].back()["position"].get<std::vector<double>>();
  EXPECT_GT(box[0], 0.62) << "the box stayed on the ledge";
  EXPECT_LT(box[1], 1.2) << "the box did not fall";

  // The net: the hand and forearm come down onto it at (0.5, 0.05), where they are at 1.8-2.0 s,
  // the hand's joint at 0.72 m. The net's animator holds the nodes out of the user inside its
  // sub-steps (nodes/massspring/README.md, "Net / captured user, inside the sub-steps"), so the
  // floating net under the hand is pressed far below its mirror image across the net's middle
  // (x 1.25): measured 0.660 against 0.909 m (25 cm), the nearest node 1.9 cm from the body.
  // The user's contacts as forces of the interactor, held over each step (the net not given the
  // user, user-contacts on), left 3.0 cm (0.878 against 0.908 m) with the hand below the net:
  // the nodes had crossed it, and this test fails on its first two checks below
  // (examples/camera_user/README.md).
  const auto net = netPositions(readFile(dir.file("one/net-final.txt")));
  ASSERT_EQ(net.size(), 400u);
  const double pressed = lowestNear(net, 0.45, 0.05, 0.2);
  const double mirror = lowestNear(net, 2.05, 0.05, 0.2);
  EXPECT_LT(pressed, mirror - 0.15) << "the hand did not press the net";
  // The hand is above the net it pressed, not past it: the lowest node under it is below the
  // hand's joint, and no node is inside the user's body (its exact capsules at the last step).
  const auto track = camera::KeyframeTrack::load(example("user.keys"));
  ASSERT_TRUE(track) << track.error().message;
  const camera::SyntheticUser body(track->poseAt(0.01 * (kIterations - 1)));
  EXPECT_LT(pressed, 0.72) << "the net is above the hand";
  double closest = 1e9;
  for (const auto& p : net) closest = std::min(closest, body.signedDistance({p[0], p[1], p[2]}));
  EXPECT_GT(closest, 0.0) << "a node is inside the user";

  // The water keeps its volume within the fluid's own bound (2 %, as the dam break's).
  const auto fluid = nlohmann::json::parse(readFile(dir.file("one/fluid-final.json")));
  const double v0 = fluid["initialVolume"].get<double>(), v1 = fluid["volume"].get<double>();
  EXPECT_NEAR(v1 / v0, 1.0, 0.02);
  std::printf(
      "box at (%.3f, %.3f, %.3f); net under the hand %.3f m, at the mirror %.3f m, nearest node "
      "to the body %.3f m; volume %+.3f %%\n",
      box[0], box[1], box[2], pressed, mirror, closest, 100 * (v1 / v0 - 1));
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

}  // namespace
}  // namespace vrflow::testing
