// examples/camera_user_small through the real `vrflow run`, as its README says to run it: the
// user's right hand pushes the crate off the table onto the floor, then its left hand presses the
// net; every module runs every iteration and nothing is left behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "process_helpers.hpp"
#include "user_scenes.hpp"
#include "vrflow/camera/capture_latency.hpp"
#include "vrflow/camera/capture_stamps.hpp"

namespace vrflow::testing {
namespace {

TEST(CameraUserExample, TheHandPushesTheCrateOffTheTableAndPressesTheNet) {
  TempDir dir;
  const int iterations = 250;
  const auto result =
      runCommand({"/bin/sh", "-c",
                  "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' run '" + sourceDir() +
                      "/examples/camera_user_small/camera_user_small.xml' -n " +
                      std::to_string(iterations) + " --report report.json"},
                 300);
  ASSERT_EQ(result.exitCode, 0) << result.out << result.err;
  const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
  EXPECT_EQ(report["status"], "ok");
  std::set<std::string> ran;
  for (const auto& module : report["modules"]) {
    EXPECT_EQ(module["iterations"].get<int>(), iterations) << module["id"];
    ran.insert(module["id"].get<std::string>());
  }
  EXPECT_EQ(ran, (std::set<std::string>{"truth", "user", "bodies", "contacts", "field", "net",
                                        "net-contacts", "view"}));
  // The viewer drew iterations 0, 50, ..., 200 (the user among the objects).
  for (int frame = 0; frame < 5; ++frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frames/frame_%06d.png", frame);
    EXPECT_EQ(access(dir.file(name).c_str(), F_OK), 0) << name;
  }

  // The crate (third body) started on the table top (y 1.5, z 0.8, the table's far edge at
  // z 0.95) and ends on the floor beyond the edge.
  const auto state = nlohmann::json::parse(readFile(dir.file("bodies-final.json")));
  const auto crate = state["bodies"][2]["position"].get<std::vector<double>>();
  EXPECT_LT(crate[1], 0.2);
  EXPECT_GT(crate[1], 0.05);
  EXPECT_GT(crate[2], 0.95);

  // The net (its plane at 1.15 m) is pressed under the left hand (x 0.66, z 0.6).
  const auto net = netPositions(readFile(dir.file("net-final.txt")));
  ASSERT_EQ(net.size(), 169u);
  double lowest = 1e9;
  for (const auto& p : net) lowest = std::min(lowest, p[1]);
  EXPECT_LT(lowest, 1.15 - 0.04);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

// Issue 21's capture-to-interactor latency: `vrflow record` of the rigid and mass-spring
// interactors' outputs; each message an interactor sends at its iteration k carries the capture
// iteration c of the user frame it solved against (stamped by user-truth, carried by the user
// animator), so k - c is the latency in frames. The network joins every chain in lockstep (no
// initial message between the capture and the interactors): 0 frames, against the 2.
TEST(CameraUserExample, TheInteractorsUseEachFrameInTheIterationItWasCaptured) {
  TempDir dir;
  const auto result = runCommand(
      {"/bin/sh", "-c",
       "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' record '" + sourceDir() +
           "/examples/camera_user_small/camera_user_small.xml' --connections "
           "contacts.forces,net-contacts.forces,user.objects -o latency.vrrec -n 30 --no-progress"},
      300);
  ASSERT_EQ(result.exitCode, 0) << result.out << result.err;
  const auto used =
      camera::latencyFrames(dir.file("latency.vrrec"), camera::kUsedCaptureIterationStamp);
  ASSERT_TRUE(used) << used.error().message;
  for (const char* interactor : {"contacts.forces", "net-contacts.forces"}) {
    ASSERT_EQ(used->count(interactor), 1u) << interactor << " carried no capture iteration";
    const auto& frames = used->at(interactor);
    std::printf("%s: %llu messages, capture to use %lld..%lld frames, first use at %lld\n",
                interactor, static_cast<unsigned long long>(frames.messages),
                static_cast<long long>(frames.min), static_cast<long long>(frames.max),
                static_cast<long long>(frames.firstUseIteration));
    EXPECT_EQ(frames.messages, 30u) << interactor;
    EXPECT_EQ(frames.firstUseIteration, 0) << interactor;
    EXPECT_EQ(frames.min, 0) << interactor;
    EXPECT_EQ(frames.max, 0) << interactor;
  }
  // The user animator's objects carry the frame they were made from.
  const auto made =
      camera::latencyFrames(dir.file("latency.vrrec"), camera::kCaptureIterationStamp);
  ASSERT_TRUE(made) << made.error().message;
  ASSERT_EQ(made->count("user.objects"), 1u);
  EXPECT_EQ(made->at("user.objects").max, 0);
  EXPECT_EQ(made->at("user.objects").messages, 30u);
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
}

TEST(CameraUserExample, ALatencyReadOfAMissingRecordingIsOneErrorNamingTheFile) {
  TempDir dir;
  const auto missing =
      camera::latencyFrames(dir.file("none.vrrec"), camera::kUsedCaptureIterationStamp);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("none.vrrec"), std::string::npos)
      << missing.error().message;
}

}  // namespace
}  // namespace vrflow::testing
