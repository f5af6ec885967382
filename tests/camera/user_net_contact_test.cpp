// addUserContacts (nodes/massspring) against a user given by its distance field: a thin slab,
// the shape of a hand seen from the side, moving down onto a net node by voxel steps.
#include <gtest/gtest.h>

#include <cmath>

#include "vrflow/camera/user_surface.hpp"
#include "vrflow/massspring/contact.hpp"

namespace vrflow::massspring {
namespace {

// A horizontal slab 9 cm thick centred at height `centre`, as a user's distance field sampled on
// a 2 cm grid over a 0.6 m cube around the origin (x and z), heights 0.2 to 0.8 m.
camera::UserSurface slabUser(double centre) {
  camera::UserSurface user;
  user.id = 7;
  user.dims = {31, 31, 31};
  user.spacing = 0.02;
  user.origin = {-0.3, 0.2, -0.3};
  user.sdf.resize(31 * 31 * 31);
  for (int k = 0; k < 31; ++k)
    for (int j = 0; j < 31; ++j)
      for (int i = 0; i < 31; ++i)
        user.sdf[static_cast<std::size_t>(i + 31 * (j + 31 * k))] =
            static_cast<float>(std::abs(user.origin[1] + 0.02 * j - centre) - 0.045);
  user.bounds = {{-0.3, centre - 0.045, -0.3}, {0.3, centre + 0.045, 0.3}};
  return user;
}

// A 3 x 3 net, 10 cm, in the plane y = 0.44 around the origin, corners pinned.
Net smallNet() {
  GridParams grid;
  grid.n = 3;
  grid.m = 3;
  grid.origin = {0, 0.44, 0};
  auto net = generateGrid(grid);
  EXPECT_TRUE(net) << net.error().message;
  return std::move(*net);
}

// The vertical force on the net's middle node (index 4) after one call.
double middleForce(const Net& net, const camera::UserSurface& user, UserContactMemory* memory) {
  ContactForces out;
  addUserContacts({{1, net}}, {{user.id, &user}}, ContactParams{}, out, memory);
  const auto found = out.nodeForces.find(1);
  return found == out.nodeForces.end() ? 0.0 : found->second[3 * 4 + 1];
}

TEST(UserNetContact, ANodeTheHandSwallowsPastItsMiddleIsPushedOutOfTheSideItCameFrom) {
  const Net net = smallNet();
  // The slab's bottom 3.5 cm above the node, then one 9 cm step down: the node (y 0.44) is
  // inside, 1 cm above the slab's middle (0.43), so the nearest surface is the top.
  const auto before = slabUser(0.52);
  const auto after = slabUser(0.43);
  UserContactMemory memory;
  EXPECT_EQ(middleForce(net, before, &memory), 0.0);
  EXPECT_LT(middleForce(net, after, &memory), 0.0) << "pushed up, through the hand";
  // Without the memory the distance field's gradient sends it up, out of the far side.
  EXPECT_GT(middleForce(net, after, nullptr), 0.0);
}

TEST(UserNetContact, ANodeThatCameFromAboveIsPushedUp) {
  const Net net = smallNet();
  const auto before = slabUser(0.36);  // the slab's top 3.5 cm below the node
  const auto after = slabUser(0.45);   // up 9 cm: the node 1 cm below its middle
  UserContactMemory memory;
  EXPECT_EQ(middleForce(net, before, &memory), 0.0);
  EXPECT_GT(middleForce(net, after, &memory), 0.0);
}

}  // namespace
}  // namespace vrflow::massspring
