// The captured user in the water, through the real `vrflow run`: camera/user-truth feeds
// camera/user-animator, whose user object reaches the fluid module. A hand that dips into a pool
// and sweeps through it sets the water moving (a still user leaves the pool still) while the
// water's volume stays within the fluid's own bound (2 %, the dam break's in
// nodes/fluid/README.md), and the same run twice gives the same bits. The user takes no events at
// all (the user animator has no input for them): nothing pushes it.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"
#include "user_scenes.hpp"

namespace vrflow::testing {
namespace {

// A 0.64 x 0.48 x 0.64 m tank of 4 cm cells around the right hand (at x -0.33, y 1.52, z 0.58,
// 4.5 cm radius), filled to 1.4 m: the hand's lowest point is 7.5 cm above the water.
std::string fluidApp(const TempDir& dir, const std::vector<std::pair<double, msg::Vec3>>& keys) {
  const auto file = dir.write("user.keys", userKeys(keys));
  const auto user = userModules(file, 48, {-0.7, 0.45, -0.5}, 1.4, "water.objects");
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="user-water" version="1">
  <hosts><host id="local" address="127.0.0.1"/></hosts>
  <modules>
    <module id="water" package="fluid" type="fluid" host="local">
      <param name="nx" value="16"/>
      <param name="ny" value="12"/>
      <param name="nz" value="16"/>
      <param name="cell-size" value="0.04"/>
      <param name="origin" value="-0.65 1.0 0.26"/>
      <param name="fill-min" value="-0.65 1.0 0.26"/>
      <param name="fill-max" value="-0.01 1.4 0.9"/>
      <param name="particles-every" value="0"/>
      <param name="state-file" value=")" +
         dir.file("water.json") + R"("/>
    </module>
)" + user.modules +
         R"(  </modules>
  <connections>
)" + user.connections +
         R"(  </connections>
</application>
)";
}

nlohmann::json runWater(const TempDir& dir, const std::string& app, int iterations) {
  const auto file = dir.write("app.xml", app);
  const auto result =
      runCommand({binDir() + "/vrflow", "run", file, "-n", std::to_string(iterations)}, 300);
  EXPECT_EQ(result.exitCode, 0) << result.out << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_TRUE(vrflowShmEntries().empty());
  return nlohmann::json::parse(readFile(dir.file("water.json")));
}

TEST(UserInWater, AHandSweepingThroughThePoolStirsItAndKeepsItsVolume) {
  // Down 15 cm (7.5 cm into the water) by 0.4 s, then 20 cm along +x by 0.9 s.
  const std::vector<std::pair<double, msg::Vec3>> sweep{
      {0.1, {0, 0, 0}}, {0.4, {0, -0.15, 0}}, {0.9, {0.2, -0.15, 0}}};
  TempDir dir;
  const std::string app = fluidApp(dir, sweep);
  const auto swept = runWater(dir, app, 100);
  TempDir stillDir;
  const auto still = runWater(stillDir, fluidApp(stillDir, {{0.0, {0, 0, 0}}}), 100);

  const double v0 = swept["initialVolume"].get<double>(), v1 = swept["volume"].get<double>();
  const double speed = swept["maxSpeed"].get<double>();
  const double stillSpeed = still["maxSpeed"].get<double>();
  std::printf(
      "volume %.6f -> %.6f m^3 (%+.3f %%), fastest particle %.3f m/s at the end; with a "
      "still user %+.3f %% and %.5f m/s\n",
      v0, v1, 100 * (v1 - v0) / v0, speed,
      100 * (still["volume"].get<double>() / still["initialVolume"].get<double>() - 1), stillSpeed);
  EXPECT_LT(std::abs(v1 - v0), 0.02 * v0);
  EXPECT_EQ(swept["particles"], still["particles"]);
  // The swept water still moves a tenth of a second after the hand stopped; the still pool not.
  EXPECT_GT(speed, 0.05);
  EXPECT_LT(stillSpeed, 0.01);
  TempDir again;
  const auto repeated = runWater(again, fluidApp(again, sweep), 100);
  EXPECT_EQ(repeated["centroid"], swept["centroid"]);
  EXPECT_EQ(repeated["volume"], swept["volume"]);
  EXPECT_EQ(repeated["particlesMax"], swept["particlesMax"]);
}

}  // namespace
}  // namespace vrflow::testing
