#include "final_state.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

// The fluid module's state-file: the surface level and the per-body submerged fraction that the
// examples' tests rely on.
namespace vrflow::fluid {
namespace {

FluidSettings grid4() {
  FluidSettings s;
  s.nx = 4;
  s.ny = 8;
  s.nz = 4;
  s.cellSize = 0.1;
  return s;
}

// One particle per column at height y, in column (i, k).
void addColumnTop(std::vector<float>& xyz, int i, int k, double y) {
  xyz.insert(xyz.end(), {static_cast<float>(0.1 * i + 0.05), static_cast<float>(y),
                         static_cast<float>(0.1 * k + 0.05)});
}

TEST(FluidFinalState, SurfaceLevelIsTheMedianColumnTopDespiteASplashAndABody) {
  std::vector<float> xyz;
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < 4; ++i) addColumnTop(xyz, i, k, 0.1 * (k + i) / 100.0);  // deep particles
    for (int i = 0; i < 4; ++i) addColumnTop(xyz, i, k, 0.40);                   // the surface
  }
  addColumnTop(xyz, 0, 0, 0.75);  // a splash
  addColumnTop(xyz, 1, 1, 0.70);  // another
  // Columns under a body: the particles stop at its bottom; three of sixteen columns.
  for (auto* p = xyz.data(); p + 2 < xyz.data() + xyz.size(); p += 3) {
    const bool underBody = (p[0] > 0.2 && p[0] < 0.3 && p[2] < 0.3);
    if (underBody && p[1] > 0.3f) p[1] = 0.25f;
  }
  EXPECT_NEAR(surfaceLevel(grid4(), xyz), 0.40, 1e-6);
  EXPECT_NEAR(surfaceLevel(grid4(), {}), 0.0, 0.0) << "no particle: the grid's floor";
}

TEST(FluidFinalState, WritesJsonWithVolumeCentroidAndSubmergedFractions) {
  FinalState st;
  st.settings = grid4();
  st.steps = 3;
  st.time = 0.03;
  st.initialVolume = 0.1;
  st.volume = 0.101;
  for (int k = 0; k < 4; ++k) {
    for (int i = 0; i < 4; ++i) addColumnTop(st.particles, i, k, 0.40);
  }
  RigidBody floating;
  floating.id = 7;
  floating.shape = msg::Shape::box({0.1, 0.1, 0.1});
  floating.position = {0.2, 0.45, 0.2};  // spans 0.35..0.55: a quarter under 0.40
  RigidBody ground;
  ground.id = 8;
  ground.kinematic = true;
  ground.shape = msg::Shape::box({1, 0.5, 1});
  ground.position = {0.2, -0.5, 0.2};
  st.bodies = {floating, ground};
  BodyForce f;
  f.id = 7;
  f.force = {0, 2.5, 0};
  f.cells = 12;
  st.forces = {f, BodyForce{}};

  const std::string path = ::testing::TempDir() + "fluid-final-state-test.json";
  ASSERT_TRUE(writeFinalState(path, st).ok());
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const auto j = nlohmann::json::parse(text.str());
  std::remove(path.c_str());
  EXPECT_EQ(j["steps"].get<int>(), 3);
  EXPECT_EQ(j["particles"].get<int>(), 16);
  EXPECT_DOUBLE_EQ(j["initialVolume"].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(j["volume"].get<double>(), 0.101);
  EXPECT_NEAR(j["level"].get<double>(), 0.40, 1e-6);
  EXPECT_NEAR(j["centroid"][0].get<double>(), 0.20, 1e-6);
  EXPECT_NEAR(j["centroid"][1].get<double>(), 0.40, 1e-6);
  ASSERT_EQ(j["bodies"].size(), 2u);
  EXPECT_EQ(j["bodies"][0]["id"].get<unsigned long long>(), 7u);
  EXPECT_NEAR(j["bodies"][0]["submerged"].get<double>(), 0.25, 1e-6);
  EXPECT_EQ(j["bodies"][0]["faces"].get<int>(), 12);
  EXPECT_DOUBLE_EQ(j["bodies"][0]["force"][1].get<double>(), 2.5);
  EXPECT_TRUE(j["bodies"][1]["kinematic"].get<bool>());
  EXPECT_DOUBLE_EQ(j["bodies"][1]["submerged"].get<double>(), 1.0) << "wholly under the level";
}

TEST(FluidFinalState, UnwritablePathIsAClearError) {
  const auto status = writeFinalState("/nonexistent-folder/state.json", FinalState{});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("/nonexistent-folder/state.json"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::fluid
