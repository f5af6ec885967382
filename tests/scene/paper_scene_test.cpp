// The demo scene (examples/paper_scene: figures 4 and 5 of the paper without the fluid) through
// the real `vrflow run`: every module of the figures in its own process, wired by the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "process_helpers.hpp"
#include "vrflow/massspring/net.hpp"
#include "vrflow/massspring/objects.hpp"
#include "vrflow/massspring/solver.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/record/reader.hpp"
#include "vrflow/rigid/contact_solver.hpp"
#include "vrflow/rigid/scene.hpp"

namespace vrflow::testing {
namespace {

const std::string kApp = "/examples/paper_scene/paper_scene.xml";

// Runs the scene in `dir` (its outputs land there) for `iterations`, with `vrflow run` or, with
// `options` such as "--connections ...", `vrflow record`.
CommandResult runScene(const TempDir& dir, int iterations, const std::string& command = "run",
                       const std::string& options = "") {
  return runCommand(
      {"/bin/sh", "-c",
       "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' " + command + " '" + sourceDir() +
           kApp + "' -n " + std::to_string(iterations) + " --report report.json " + options},
      420);
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
    // The four objects on the net ride its swing a little longer since the net no longer
    // freezes at its stretch limits (issue 26): at most 0.15 m/s here; the 300-iteration test
    // (TheNetStaysBounded...) holds them below 0.1 m/s at its end.
    const bool onNet = b["boundsMin"][1].get<double>() > 0.3;
    EXPECT_LT(norm(velocity), onNet ? 0.15 : 0.1) << "body " << i << " still moves";
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

// The net's state after every iteration, from a recording of the scene: the net integrates its
// springs in 3 sub-steps (omega h 1.0); with the paper's spring interactor once per 10 ms step
// (omega dt 3.0) it jittered at its stretch limits and never let its objects rest.
TEST(PaperScene, TheNetStaysBoundedWithinItsLimitsMovesWhileObjectsLandAndHoldsThemAtRest) {
  TempDir dir;
  const int iterations = 300;
  const auto result = runScene(dir, iterations, "record",
                               "--no-progress --connections net.objects,bodies.objects -o s.vrrec");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  auto reader = record::RecordingReader::open(dir.file("s.vrrec"));
  ASSERT_TRUE(reader) << reader.error().message;
  std::uint32_t netConnection = 0;
  for (std::uint32_t c = 0; c < (*reader)->connections().size(); ++c) {
    if ((*reader)->connections()[c].module == "net") netConnection = c;
  }
  // Per iteration (0: the net as added, 1..299: after each step): the net's fastest node, kinetic
  // energy, worst length / limit, whether its positions are bit for bit those of the iteration
  // before; the fastest dynamic rigid between the net's posts (x in 0.3..2.2 m).
  std::vector<double> fastestNode(iterations, -1), kinetic(iterations, -1), limit(iterations, -1),
      fastestOnNet(iterations, 0);
  std::vector<int> unchanged(iterations, 0);
  massspring::SceneCopy nets, bodies;
  std::vector<double> before;
  bool finite = true;
  for (std::size_t chunk = 0; chunk < (*reader)->chunks().size(); ++chunk) {
    auto records = (*reader)->readChunk(chunk);
    ASSERT_TRUE(records) << records.error().message;
    for (const auto& record : *records) {
      auto view = msg::MessageView::parse(record.message);
      ASSERT_TRUE(view) << view.error().message;
      const auto i = static_cast<std::size_t>(record.iteration);
      ASSERT_LT(i, static_cast<std::size_t>(iterations));
      if (record.connection != netConnection) {
        ASSERT_TRUE(bodies.apply(*view));
        for (const auto& [id, body] : bodies.rigids()) {
          if (!(body.mass > 0) || !std::isfinite(body.mass) || body.position[0] < 0.3 ||
              body.position[0] > 2.2)
            continue;
          fastestOnNet[i] = std::max(
              fastestOnNet[i],
              norm({body.linearVelocity[0], body.linearVelocity[1], body.linearVelocity[2]}));
        }
        continue;
      }
      ASSERT_TRUE(nets.apply(*view));
      ASSERT_EQ(nets.nets().size(), 1u);
      const auto& net = nets.nets().begin()->second;
      for (std::size_t n = 0; n < net.nodeCount(); ++n) {
        const auto v = net.velocity(n);
        const double speed = norm({v[0], v[1], v[2]});
        finite = finite && std::isfinite(speed) && std::isfinite(net.position(n)[0]) &&
                 std::isfinite(net.position(n)[1]) && std::isfinite(net.position(n)[2]);
        fastestNode[i] = std::max(fastestNode[i], speed);
      }
      kinetic[i] = massspring::kineticEnergy(net);
      limit[i] = massspring::maxConstraintRatio(net);
      unchanged[i] = net.positions == before;
      before = net.positions;
    }
  }
  ASSERT_TRUE(finite) << "a node position or velocity is not finite";
  int landing = 0, frozen = 0;
  double fastest = 0, worstLimit = 0, lastKinetic = 0;
  for (int i = 1; i < iterations; ++i) {
    ASSERT_GE(fastestNode[i], 0) << "iteration " << i << " of the net was not recorded";
    fastest = std::max(fastest, fastestNode[i]);
    worstLimit = std::max(worstLimit, limit[i]);
    if (i > iterations - 50) lastKinetic = std::max(lastKinetic, kinetic[i]);
    if (fastestOnNet[i] > 0.05) {
      ++landing;
      frozen += unchanged[i];
    }
  }
  std::printf(
      "net: fastest node %.3f m/s, worst length/limit %.12f, kinetic energy over the last "
      "50 iterations <= %.3g J, %d landing iterations, %d of them bit-identical\n",
      fastest, worstLimit, lastKinetic, landing, frozen);
  // Measured: 3.2 m/s, 0.13 J (objects still settling); with the springs once per step (the
  // paper's spring interactor, the file before issue 26) 7.6 m/s and 5.2 J, and three of the
  // four objects still moving at 0.14 to 0.62 m/s.
  EXPECT_LT(fastest, 5.0);
  EXPECT_LE(worstLimit, 1.0 + 1e-9);
  EXPECT_GT(landing, 20);
  EXPECT_EQ(frozen, 0) << "the net froze while objects landed on it";
  EXPECT_LT(lastKinetic, 0.5) << "the net still jitters";

  // The four objects rest on the net: above the ground, between the posts, still.
  const auto state = nlohmann::json::parse(readFile(dir.file("bodies-final.json")));
  int resting = 0;
  for (const auto& b : state["bodies"]) {
    const double x = b["position"][0].get<double>();
    if (b["kinematic"].get<bool>() || x < 0.3 || x > 2.2) continue;
    EXPECT_GT(b["boundsMin"][1].get<double>(), 0.3) << "fell through the net";
    EXPECT_LT(norm(b["linearVelocity"].get<std::vector<double>>()), 0.1) << "still moves";
    ++resting;
  }
  EXPECT_EQ(resting, 4);
}

}  // namespace
}  // namespace vrflow::testing
