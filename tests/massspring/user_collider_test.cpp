// nodes/massspring/user_collider.hpp: the captured user as a kinematic collider inside the net's
// sub-steps (user_collider.hpp): a sphere's distance field and a uniform surface velocity,
// re-sampled where the sphere is at each outer step as the user animator publishes one frame per
// step.
#include "vrflow/massspring/user_collider.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "vrflow/massspring/solver.hpp"

namespace vrflow::massspring {
namespace {

constexpr double kRadius = 0.1;

// A sphere of radius kRadius at `centre` moving at `velocity`, as a user's fields on a 1 cm grid
// over a 0.8 m cube around it.
camera::UserSurface sphereUser(const msg::Vec3& centre, const msg::Vec3& velocity,
                               double radius = kRadius) {
  camera::UserSurface user;
  user.id = 9;
  constexpr std::uint32_t kCells = 81;
  user.dims = {kCells, kCells, kCells};
  user.spacing = 0.01;
  user.origin = {centre[0] - 0.4, centre[1] - 0.4, centre[2] - 0.4};
  user.position = centre;
  user.bounds = {{centre[0] - radius, centre[1] - radius, centre[2] - radius},
                 {centre[0] + radius, centre[1] + radius, centre[2] + radius}};
  user.sdf.resize(std::size_t{kCells} * kCells * kCells);
  user.velocity.resize(3 * user.sdf.size());
  std::size_t cell = 0;
  for (std::uint32_t k = 0; k < kCells; ++k)
    for (std::uint32_t j = 0; j < kCells; ++j)
      for (std::uint32_t i = 0; i < kCells; ++i, ++cell) {
        const double x = user.origin[0] + 0.01 * i - centre[0];
        const double y = user.origin[1] + 0.01 * j - centre[1];
        const double z = user.origin[2] + 0.01 * k - centre[2];
        user.sdf[cell] = static_cast<float>(std::sqrt(x * x + y * y + z * z) - radius);
        for (int a = 0; a < 3; ++a) user.velocity[3 * cell + a] = static_cast<float>(velocity[a]);
      }
  return user;
}

// One free 20 g node, no springs.
Net oneNode(const msg::Vec3& position, const msg::Vec3& velocity) {
  Net net;
  net.positions = {position[0], position[1], position[2]};
  net.velocities = {velocity[0], velocity[1], velocity[2]};
  net.masses = {0.02};
  net.pinned = {0};
  return net;
}

struct Run {
  Net net;
  msg::Vec3 centre;
  double distance = 0;  ///< from the node to the sphere's surface at the end
};

// Steps the node for `steps` outer steps of 10 ms (10 sub-steps) against the sphere starting at
// `centre` and moving at `velocity`, with `gravity`; the user's frame is taken at each step's
// start.
Run simulate(Net net, msg::Vec3 centre, const msg::Vec3& velocity, const msg::Vec3& gravity,
             int steps, int substeps = 10) {
  StepOptions options;
  options.substeps = substeps;
  options.gravity = gravity;
  UserColliderMemory memory;
  UserColliders colliders;
  colliders.memory = &memory;
  for (int s = 0; s < steps; ++s) {
    const auto user = sphereUser(centre, velocity);
    colliders.users = {{user.id, &user}};
    step(net, {}, options, &colliders);
    for (int a = 0; a < 3; ++a) centre[a] += velocity[a] * options.dt;
  }
  Run run{net, centre, 0};
  const auto p = net.position(0);
  run.distance = std::hypot(p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]) - kRadius;
  return run;
}

TEST(UserCollider, ANodeFallingOntoARisingSphereStopsAtItsSurfaceAndRisesWithIt) {
  // 20 cm above the sphere's top, falling at 3 m/s; the sphere rises at 0.5 m/s.
  const msg::Vec3 up{0, 0.5, 0};
  const auto run = simulate(oneNode({0, 0.3, 0}, {0, -3, 0}), {0, 0, 0}, up, {0, -9.81, 0}, 50);
  // At its surface (the thickness, 2 cm, within the sphere's travel over one step), above it.
  EXPECT_NEAR(run.distance, 0.02, 0.006);
  EXPECT_GT(run.net.position(0)[1], run.centre[1] + kRadius);
  // Carried up at the sphere's speed: set to it when a frame catches the node, then slowed by
  // gravity over the step while the frame is held (at most g dt).
  EXPECT_LE(run.net.velocity(0)[1], 0.5 + 1e-9);
  EXPECT_GE(run.net.velocity(0)[1], 0.5 - 9.81 * 0.01 - 1e-9);
}

TEST(UserCollider, ANodeRisingIntoASinkingSphereFromBelowStopsAtItsSurface) {
  // 20 cm under the sphere's bottom, rising at 3 m/s, no gravity; the sphere sinks at 0.5 m/s.
  const msg::Vec3 down{0, -0.5, 0};
  const auto run = simulate(oneNode({0, -0.3, 0}, {0, 3, 0}), {0, 0, 0}, down, {0, 0, 0}, 50);
  EXPECT_NEAR(run.distance, 0.02, 0.006);
  EXPECT_LT(run.net.position(0)[1], run.centre[1] - kRadius) << "the node crossed the sphere";
  EXPECT_NEAR(run.net.velocity(0)[1], -0.5, 1e-6) << "pushed down at the sphere's speed";
}

TEST(UserCollider, ANodeRestingOnAMovingSphereIsCarriedByFriction) {
  // On the sphere's top, the sphere moving sideways and up for 1 s.
  const msg::Vec3 velocity{0.3, 0.2, 0};
  const auto run =
      simulate(oneNode({0, kRadius + 0.02, 0}, {0, 0, 0}), {0, 0, 0}, velocity, {0, -9.81, 0}, 100);
  const auto p = run.net.position(0);
  EXPECT_NEAR(run.distance, 0.02, 0.006);
  EXPECT_LT(std::abs(p[0] - run.centre[0]), 0.03) << "the sphere slid out from under the node";
  EXPECT_NEAR(run.net.velocity(0)[0], 0.3, 0.03);
  EXPECT_LE(run.net.velocity(0)[1], 0.2 + 1e-9);
  EXPECT_GE(run.net.velocity(0)[1], 0.2 - 9.81 * 0.01 - 1e-9);
  // Without friction, the node stays where it was along x and falls off the side.
  StepOptions options;
  UserColliders frictionless;
  frictionless.params.friction = 0;
  UserColliderMemory memory;
  frictionless.memory = &memory;
  Net net = oneNode({0, kRadius + 0.02, 0}, {0, 0, 0});
  options.gravity = {0, -9.81, 0};
  msg::Vec3 centre{0, 0, 0};
  for (int s = 0; s < 100; ++s) {
    const auto user = sphereUser(centre, velocity);
    frictionless.users = {{user.id, &user}};
    step(net, {}, options, &frictionless);
    for (int a = 0; a < 3; ++a) centre[a] += velocity[a] * options.dt;
  }
  EXPECT_GT(std::abs(net.position(0)[0] - centre[0]), 0.1);
}

TEST(UserCollider, AFastNodeDoesNotTunnelThroughTheSphereInOneSubStep) {
  // At 100 m/s with one 10 ms sub-step the node would move 1 m, across the 20 cm sphere.
  const auto run =
      simulate(oneNode({0, 0.4, 0}, {0, -100, 0}), {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, 1, 1);
  EXPECT_NEAR(run.distance, 0.02, 1e-3);
  EXPECT_GT(run.net.position(0)[1], 0.0) << "it crossed the sphere";
  EXPECT_NEAR(run.net.velocity(0)[1], 0.0, 1e-9);
  // Tested only at the sub-step's end, it would pass.
  Net net = oneNode({0, -0.6, 0}, {0, -100, 0});
  const auto user = sphereUser({0, 0, 0}, {0, 0, 0});
  UserColliders colliders;
  colliders.users = {{user.id, &user}};
  EXPECT_EQ(collideWithUsers(net, {}, colliders), 0u);
}

TEST(UserCollider, ANodeTheUserSwallowsPastItsMiddleGoesOutOfTheSideItCameFrom) {
  // The node 2.5 cm under the sphere's bottom; the next frame jumps the sphere down 13.5 cm, so
  // the node is 1 cm over its centre, where the gradient points up: it must go out downwards.
  Net net = oneNode({0, kRadius + 0.01, 0}, {0, 0, 0});
  UserColliderMemory memory;
  UserColliders colliders;
  colliders.memory = &memory;
  const auto first = sphereUser({0, kRadius + 0.01 + 0.025 + kRadius, 0}, {0, 0, 0});
  colliders.users = {{first.id, &first}};
  std::vector<double> before = net.positions;
  EXPECT_EQ(collideWithUsers(net, before, colliders), 0u);  // below it: side remembered
  const auto second = sphereUser({0, kRadius, 0}, {0, 0, 0});
  colliders.users = {{second.id, &second}};
  before = net.positions;
  EXPECT_EQ(collideWithUsers(net, before, colliders), 1u);
  EXPECT_NEAR(net.position(0)[1], -0.02, 1e-3) << "out of the top, through the sphere";
  // Without the memory the gradient takes it out of the top.
  Net fresh = oneNode({0, kRadius + 0.01, 0}, {0, 0, 0});
  colliders.memory = nullptr;
  EXPECT_EQ(collideWithUsers(fresh, {}, colliders), 1u);
  EXPECT_NEAR(fresh.position(0)[1], 2 * kRadius + 0.02, 1e-3);
}

// The lowest point of a 3 x 3 net (10 cm, corners pinned, 20 g nodes, 1 kN/m) after a 3 cm
// ball came down at 1 m/s onto the middle of one of its cells, 20 cm below the net's plane.
double lowestAfterABallThroughACell(bool withSurface) {
  GridParams grid;
  grid.n = 3;
  grid.m = 3;
  grid.mass = 9 * 0.02;
  grid.stiffness = 1000;
  grid.maxStretch = 0;
  auto net = generateGrid(grid).value();
  if (!withSurface) net.surface.clear();
  StepOptions options;
  UserColliderMemory memory;
  UserColliders colliders;
  colliders.memory = &memory;
  msg::Vec3 centre{0.05, 0.1, 0.05};
  double lowest = 0;
  for (int s = 0; s < 30; ++s) {
    const auto ball = sphereUser(centre, {0, -1, 0}, 0.03);
    colliders.users = {{ball.id, &ball}};
    step(net, {}, options, &colliders);
    centre[1] -= 0.01;
    for (std::size_t i = 0; i < net.nodeCount(); ++i) lowest = std::min(lowest, net.position(i)[1]);
  }
  return lowest;
}

TEST(UserCollider, ABallNarrowerThanTheNetsSpacingPressesItAndDoesNotPassBetweenItsNodes) {
  // The ball's bottom ends 20 cm under the net's plane: the net under it must go down with it.
  EXPECT_LT(lowestAfterABallThroughACell(true), -0.15);
  // Tested at the nodes only, it passes between them (9 cm apart along the cell's diagonal
  // from its centre, the ball 3 cm).
  EXPECT_GT(lowestAfterABallThroughACell(false), -0.02);
}

TEST(UserCollider, TheSurfaceSweepsFromTheFrameBeforeToTheLastOverTheSubSteps) {
  // A node at the thickness above the sphere's top; the last frame has the sphere 1 cm higher.
  const auto before = sphereUser({0, 0, 0}, {0, 1, 0});
  const auto last = sphereUser({0, 0.01, 0}, {0, 1, 0});
  UserColliders colliders;
  colliders.users = {{last.id, &last}};
  colliders.previous = {{before.id, &before}};
  const double top = kRadius + 0.02;
  // One tenth of the way (the first of 10 sub-steps): the node rises one tenth of the jump.
  Net net = oneNode({0, top, 0}, {0, 0, 0});
  EXPECT_EQ(collideWithUsers(net, net.positions, colliders, 0.1), 1u);
  EXPECT_NEAR(net.position(0)[1], top + 0.001, 2e-4);
  EXPECT_NEAR(net.velocity(0)[1], 1.0, 1e-6) << "at the surface's speed";
  // At the end of the step, the last frame.
  net = oneNode({0, top, 0}, {0, 0, 0});
  EXPECT_EQ(collideWithUsers(net, net.positions, colliders, 1.0), 1u);
  EXPECT_NEAR(net.position(0)[1], top + 0.01, 2e-4);
  // Without the frame before, the whole jump at once.
  colliders.previous.clear();
  net = oneNode({0, top, 0}, {0, 0, 0});
  EXPECT_EQ(collideWithUsers(net, net.positions, colliders, 0.1), 1u);
  EXPECT_NEAR(net.position(0)[1], top + 0.01, 2e-4);
}

TEST(UserCollider, RejectsBadParameters) {
  EXPECT_FALSE(validateUserColliderParams({0, 0.5}));
  EXPECT_FALSE(validateUserColliderParams({0.02, -1}));
  EXPECT_TRUE(validateUserColliderParams({0.02, 0.5}));
}

}  // namespace
}  // namespace vrflow::massspring
