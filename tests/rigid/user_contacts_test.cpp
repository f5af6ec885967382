// Rigid bodies against a captured user (user_contacts.hpp, the user part of the contact
// solver): a user is an immovable solid given by its distance field on a grid, its surface moving
// with its velocity field. A body found inside the user is pushed out gently, and a moving
// surface pushes a body at its own speed, even where the user's field swallows part of the body.
#include "vrflow/rigid/user_contacts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vrflow/camera/user_surface.hpp"
#include "vrflow/rigid/world.hpp"

namespace vrflow::rigid {
namespace {

constexpr double kDt = 0.01;
constexpr int kCells = 61;  // 2 cm cells over a 1.2 m cube around the origin

// A user given by its signed distance `distance(x, y, z)` (m, negative inside) sampled on the
// grid, whose surface moves at `velocity` (the same at every cell), bounds from its inside cells.
template <typename Distance>
camera::UserSurface gridUser(Distance distance, const Vec3& velocity) {
  camera::UserSurface user;
  user.id = 9;
  user.dims = {kCells, kCells, kCells};
  user.spacing = 0.02;
  user.origin = {-0.6, -0.6, -0.6};
  user.bounds = {{1e9, 1e9, 1e9}, {-1e9, -1e9, -1e9}};
  for (int k = 0; k < kCells; ++k)
    for (int j = 0; j < kCells; ++j)
      for (int i = 0; i < kCells; ++i) {
        const Vec3 p{-0.6 + 0.02 * i, -0.6 + 0.02 * j, -0.6 + 0.02 * k};
        const double d = distance(p[0], p[1], p[2]);
        user.sdf.push_back(static_cast<float>(d));
        for (double v : velocity) user.velocity.push_back(static_cast<float>(v));
        if (d > 0) continue;
        for (int a = 0; a < 3; ++a) {
          user.bounds.min[a] = std::min(user.bounds.min[a], p[a]);
          user.bounds.max[a] = std::max(user.bounds.max[a], p[a]);
        }
      }
  return user;
}

// A fist: a ball of 10 cm radius centred at (x, 0, 0).
camera::UserSurface fistUser(double x, const Vec3& velocity) {
  return gridUser([x](double px, double py, double pz) { return std::hypot(px - x, py, pz) - 0.1; },
                  velocity);
}

// A flat hand: a plate 10 cm thick (|y| <= 5 cm) reaching from x = -0.6 to its tip at x = 0.
camera::UserSurface plateUser() {
  return gridUser(
      [](double x, double y, double) {
        const double dy = std::abs(y) - 0.05;
        if (x <= 0 && dy <= 0) return std::max(x, dy);
        return std::hypot(std::max(x, 0.0), std::max(dy, 0.0));
      },
      {0, 0, 0});
}

// A 20 cm box of 8 kg centred at (x, 0, 0), in a world without gravity.
void addBoxAt(RigidWorld& world, double x) {
  ASSERT_TRUE(world.add({makeBody(1, msg::Shape::box({0.1, 0.1, 0.1}), 8.0, {x, 0, 0})}));
}

double speed(const Body& b) {
  return asEigen(b.linearVelocity).norm();
}

// Pushes the box of `world` out of a still user for 40 steps: the fastest speed and the steps it
// spent inside (deeper than the slop, as the user's field measures its samples).
struct PushOut {
  double fastest = 0;
  int stepsInside = 0;
};

PushOut pushOut(RigidWorld& world, const camera::UserSurface& user) {
  world.solver().setUsers({{user.id, &user}});
  PushOut result;
  for (int step = 0; step < 40; ++step) {
    world.step(kDt);
    const Body& box = *world.state().find(1);
    result.fastest = std::max(result.fastest, speed(box));
    bool inside = false;
    for (const Vec3& local : surfaceSamples(box.shape, 0.01)) {
      const Vec3 p =
          msg::toVec3(asEigen(box.position) + asEigen(msg::rotate(box.orientation, local)));
      inside = inside || user.distance(p) < -world.solver().params().slop;
    }
    if (inside) ++result.stepsInside;
  }
  return result;
}

// Sequential impulses over points spread on a face leave the centre of mass within a few per cent
// of the contacts' target speed (a little rotation).
constexpr double kSolverSlack = 1.1;

TEST(UserContacts, ABoxInsideAStillUserIsPushedOutNoFasterThanTheBound) {
  // The user fills x <= 0; the box's face is 5 cm inside it. Baumgarte alone (0.2 of the depth
  // per 10 ms step) would push at 0.9 m/s; a user contact pushes at most userPushOut.
  const auto user = gridUser([](double x, double, double) { return x; }, {0, 0, 0});
  RigidWorld world(ForceField{}, ContactParams{});
  addBoxAt(world, 0.05);
  const double bound = world.solver().params().userPushOut;
  const PushOut run = pushOut(world, user);
  const Body& box = *world.state().find(1);
  std::printf("pushed out in %d steps, fastest %.3f m/s (bound %.2f), ends at (%.3f, %.3f, %.3f)\n",
              run.stepsInside, run.fastest, bound, box.position[0], box.position[1],
              box.position[2]);
  EXPECT_LE(run.fastest, kSolverSlack * bound);
  EXPECT_GT(run.fastest, 0.5 * bound) << "pushed out at all";
  EXPECT_GE(run.stepsInside, 3) << "over a few steps, not at once";
  EXPECT_LT(run.stepsInside, 40) << "out of the user";
  EXPECT_LT(std::hypot(box.position[1], box.position[2]), 0.3 * (box.position[0] - 0.05))
      << "out along the normal";
}

TEST(UserContacts, ABoxAThinUserSwallowsIsPushedOutOfOneSideNotThrown) {
  // The plate's tip is 8 cm inside the box's face at mid-height: the samples inside it see its
  // top (normal +y) or its bottom (-y) as nearest, and no velocity meets both pushes.
  const auto user = plateUser();
  RigidWorld world(ForceField{}, ContactParams{});
  addBoxAt(world, 0.02);
  const PushOut run = pushOut(world, user);
  const Body& box = *world.state().find(1);
  std::printf("swallowed box: fastest %.3f m/s, %d steps inside, ends at (%.3f, %.3f, %.3f)\n",
              run.fastest, run.stepsInside, box.position[0], box.position[1], box.position[2]);
  EXPECT_LE(run.fastest, 2 * world.solver().params().userPushOut);
  EXPECT_LT(run.stepsInside, 40) << "out of the user";
  EXPECT_GT(box.position[0] - 0.02, 2 * std::hypot(box.position[1], box.position[2]))
      << "out past the tip, the way most of the box sees the surface, not up or down";
}

TEST(UserContacts, AFistMovingAtVPushesABoxAtAboutV) {
  // The fist starts 1 cm from the box's face and moves along +x at v: the box ends moving at
  // about v, never faster than v plus the push-out bound.
  const double v = 0.4;
  RigidWorld world(ForceField{}, ContactParams{});
  addBoxAt(world, 0.21);
  double fastest = 0;
  camera::UserSurface user;
  for (int step = 0; step < 60; ++step) {
    user = fistUser(step * kDt * v, {v, 0, 0});
    world.solver().setUsers({{user.id, &user}});
    world.step(kDt);
    fastest = std::max(fastest, speed(*world.state().find(1)));
  }
  const Body& box = *world.state().find(1);
  std::printf("fist at %.2f m/s: box at (%.3f, %.3f, %.3f) m/s, fastest %.3f m/s\n", v,
              box.linearVelocity[0], box.linearVelocity[1], box.linearVelocity[2], fastest);
  EXPECT_GT(box.linearVelocity[0], 0.8 * v);
  EXPECT_LT(box.linearVelocity[0], 1.3 * v);
  EXPECT_LT(std::hypot(box.linearVelocity[1], box.linearVelocity[2]), 0.2 * v);
  EXPECT_LE(fastest, kSolverSlack * (v + world.solver().params().userPushOut));
}

}  // namespace
}  // namespace vrflow::rigid
