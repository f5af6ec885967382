// The demo scene (examples/paper_scene: figures 4 and 5 of the paper without the fluid) through
// the real `vrflow run`: every module of the figures in its own process, wired by the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "process_helpers.hpp"
#include "vrflow/massspring/net.hpp"
#include "vrflow/rigid/contact_solver.hpp"
#include "vrflow/rigid/scene.hpp"

namespace vrflow::testing {
namespace {

const std::string kApp = "/examples/paper_scene/paper_scene.xml";

// Runs the scene in `dir` (its outputs land there) for `iterations`.
CommandResult runScene(const TempDir& dir, int iterations) {
  return runCommand(
      {"/bin/sh", "-c",
       "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' run '" + sourceDir() + kApp +
           "' -n " + std::to_string(iterations) + " --report report.json"},
      240);
}

double norm(const std::vector<double>& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

TEST(PaperScene, AfterTwoHundredIterationsEverythingRestsAboveTheGroundAndApart) {
  TempDir dir;
  const int iterations = 200;
  const auto result = runScene(dir, iterations);
  ASSERT_EQ(result.exitCode, 0) << result.err;

  // Every module of figures 4 and 5 ran every iteration.
  const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
  EXPECT_EQ(report["status"], "ok");
  std::set<std::string> ran;
  for (const auto& module : report["modules"]) {
    EXPECT_EQ(module["iterations"].get<int>(), iterations) << module["id"];
    ran.insert(module["id"].get<std::string>());
  }
  EXPECT_EQ(ran, (std::set<std::string>{"bodies", "contacts", "field", "net", "net-collisions",
                                        "net-contacts", "camera"}));

  // The rigid objects: all 20 at rest, above the ground, none inside another.
  const auto state = nlohmann::json::parse(readFile(dir.file("bodies-final.json")));
  auto scene = rigid::loadScene(sourceDir() + "/examples/paper_scene/scene.json");
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(state["bodies"].size(), scene->size());
  rigid::RigidContactSolver overlap;
  int dynamic = 0;
  for (std::size_t i = 0; i < scene->size(); ++i) {
    const auto& b = state["bodies"][i];
    rigid::Body body = (*scene)[i];
    for (int k = 0; k < 3; ++k) body.position[k] = b["position"][k].get<double>();
    for (int k = 0; k < 4; ++k) body.orientation[k] = b["orientation"][k].get<double>();
    body.linearVelocity = {};
    body.angularVelocity = {};
    ASSERT_TRUE(overlap.setBody(body));
    if (b["kinematic"].get<bool>()) continue;
    ++dynamic;
    const auto velocity = b["linearVelocity"].get<std::vector<double>>();
    EXPECT_LT(norm(velocity), 0.1) << "body " << i << " still moves";
    EXPECT_LT(norm(b["angularVelocity"].get<std::vector<double>>()), 2.0) << "body " << i;
    // The ground's top face is at y = -0.002.
    EXPECT_GT(b["boundsMin"][1].get<double>(), -0.002 - 0.01)
        << "body " << i << " below the ground";
  }
  EXPECT_EQ(dynamic, 20);
  overlap.solve(0.01);
  double deepest = 0.0;
  for (const auto& contact : overlap.contacts()) deepest = std::min(deepest, contact.distance);
  EXPECT_GT(deepest, -0.02) << "two objects overlap by " << -deepest << " m";

  // Four objects were dropped onto the net: it holds them above the ground, and stays a net.
  int onTheNet = 0;
  for (const auto& b : state["bodies"]) {
    if (!b["kinematic"].get<bool>() && b["boundsMin"][1].get<double>() > 0.3) ++onTheNet;
  }
  EXPECT_EQ(onTheNet, 4);
  auto net = massspring::loadNet(dir.file("net-final.txt"));
  ASSERT_TRUE(net) << net.error().message;
  ASSERT_EQ(net->positions.size(), 3u * 400u);
  for (std::size_t i = 0; i < net->positions.size(); i += 3) {
    ASSERT_TRUE(std::isfinite(net->positions[i + 1]));
    EXPECT_GT(net->positions[i + 1], 0.2) << "node " << i / 3;
  }

  // The viewer wrote the frames: a video or one image per iteration.
  std::size_t frames = 0;
  bool video = false;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    if (entry.path().extension() == ".png") ++frames;
    if (entry.path().extension() == ".mp4" && entry.file_size() > 0) video = true;
  }
  EXPECT_TRUE(video || frames == static_cast<std::size_t>(iterations)) << frames << " frames";
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(PaperScene, TheSameRunTwiceGivesTheSameBits) {
  std::vector<std::string> digests[2];
  for (auto& run : digests) {
    TempDir dir;
    const auto result = runScene(dir, 40);
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
    for (const auto& output : report["outputs"]) {
      run.push_back(output["module"].get<std::string>() + "." + output["port"].get<std::string>() +
                    "=" + output["last_digest"].get<std::string>());
    }
    run.push_back(readFile(dir.file("bodies-final.json")));
    run.push_back(readFile(dir.file("net-final.txt")));
  }
  EXPECT_GE(digests[0].size(), 8u);
  EXPECT_EQ(digests[0], digests[1]);
}

}  // namespace
}  // namespace vrflow::testing
