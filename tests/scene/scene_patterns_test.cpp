// The network patterns of issue 7 on the demo scene (examples/scene_patterns), through the real
// `vrflow run`: the net at 10x the rigid bodies' rate (repeat + decimate), and the rigid
// interactor duplicated over 2 regions of space (scatter by bounds + gather).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"
#include "vrflow/massspring/net.hpp"

namespace vrflow::testing {
namespace {

CommandResult runPattern(const TempDir& dir, const std::string& name, int iterations) {
  return runCommand({"/bin/sh", "-c",
                     "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' run '" +
                         sourceDir() + "/examples/scene_patterns/" + name + ".xml' -n " +
                         std::to_string(iterations) + " --no-progress --report report.json"},
                    240);
}

std::map<std::string, long> iterationsOf(const TempDir& dir) {
  std::map<std::string, long> iterations;
  const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
  for (const auto& m : report["modules"]) iterations[m["id"]] = m["iterations"].get<long>();
  return iterations;
}

// The largest node speed of the final net, or infinity when a value is not finite.
double fastestNode(const massspring::Net& net) {
  double fastest = 0;
  for (std::size_t i = 0; i < net.nodeCount(); ++i) {
    const auto v = net.velocity(i);
    const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!std::isfinite(speed) || !std::isfinite(net.position(i)[1])) return INFINITY;
    fastest = std::max(fastest, speed);
  }
  return fastest;
}

// A net 10 times stiffer than the demo's (k = 3000 on 0.02 kg nodes, no stretch limit): at the
// bodies' dt = 0.01 s semi-implicit Euler is far beyond its limit (omega dt > 2) and the net
// explodes; behind repeat(10) it runs 10 steps of 0.001 s per outer iteration and stays whole,
// with the 4 objects resting on it.
TEST(ScenePatterns, TheNetAtTenTimesTheRateStaysStableWhereOneStepExplodes) {
  TempDir fast, slow;
  const auto ten = runPattern(fast, "stiff_net_10x", 300);
  ASSERT_EQ(ten.exitCode, 0) << ten.err;
  auto iterations = iterationsOf(fast);
  EXPECT_EQ(iterations["bodies"], 300);
  EXPECT_EQ(iterations["net-contacts"], 300);
  EXPECT_EQ(iterations["net"], 3000) << "--iterations counts outer iterations";
  EXPECT_EQ(iterations["springs"], 3000);
  auto net = massspring::loadNet(fast.file("net-final.txt"));
  ASSERT_TRUE(net) << net.error().message;
  EXPECT_LT(fastestNode(*net), 5.0) << "10 x dt/10: stable";
  for (std::size_t i = 0; i < net->nodeCount(); ++i) {
    EXPECT_GT(net->position(i)[1], 0.3) << "node " << i << " fell through";
    EXPECT_LE(net->position(i)[1], 0.95 + 1e-9) << "node " << i;
  }
  const auto bodies = nlohmann::json::parse(readFile(fast.file("bodies-final.json")));
  int onNet = 0;
  for (const auto& b : bodies["bodies"]) {
    const double x = b["position"][0].get<double>(), y = b["position"][1].get<double>();
    if (x > 0.3 && x < 2.2 && y > 0.4) ++onNet;  // above the ground, between the posts
  }
  EXPECT_EQ(onNet, 4) << "the net holds its 4 objects: the decimated state reached net-contacts";

  const auto one = runPattern(slow, "stiff_net_1x", 300);
  ASSERT_EQ(one.exitCode, 0) << one.err;
  net = massspring::loadNet(slow.file("net-final.txt"));
  if (net)
    EXPECT_GT(fastestNode(*net), 1e3) << "one step of 0.01 s: explodes";
  else
    SUCCEED() << "the exploded net could not even be written back: " << net.error().message;
}

// Two copies of the rigid interactor, one per region (x < 0: the box of 16 crates; x >= 0: the
// net's 4 objects), fed by scatter by bounds and joined by gather: contact islands never cross
// the cut, so every body ends in the same state, bit for bit, as with one interactor.
TEST(ScenePatterns, TheRigidInteractorDuplicatedOverTwoRegionsGivesTheSameStates) {
  TempDir one, two;
  const auto a = runPattern(one, "one_contacts", 250);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  const auto b = runPattern(two, "duplicated_contacts", 250);
  ASSERT_EQ(b.exitCode, 0) << b.err;
  const auto iterations = iterationsOf(two);
  EXPECT_EQ(iterations.at("contacts-west"), 250);
  EXPECT_EQ(iterations.at("contacts-east"), 250);
  EXPECT_EQ(readFile(one.file("bodies-final.json")), readFile(two.file("bodies-final.json")));
  EXPECT_EQ(readFile(one.file("net-final.txt")), readFile(two.file("net-final.txt")));
  // Each copy saw only its region's bodies: the west copy's forces never touch the net's.
  const auto report = nlohmann::json::parse(readFile(two.file("report.json")));
  std::map<std::string, uint64_t> bytes;
  for (const auto& c : report["connections"])
    bytes[c["to"].get<std::string>()] += c["bytes"].get<uint64_t>();
  EXPECT_GT(bytes["contacts-west.objects"], bytes["contacts-east.objects"])
      << "16 crates against 4 objects";
}

}  // namespace
}  // namespace vrflow::testing
