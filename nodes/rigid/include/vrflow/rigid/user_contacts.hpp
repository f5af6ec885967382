#pragma once
// Contacts of rigid bodies with a captured user (nodes/camera, vrflow/camera/user_surface.hpp):
// the user is a solid of infinite mass given by its signed distance field, whose surface moves
// with its own velocity field. Each dynamic body is sampled on its surface (a sphere at the point
// nearest the user, a capsule as the spheres at its ends and middle, a box on a grid over each
// face, a hull or mesh at its vertices and triangle centres) and a sample closer to the user than
// `reach` is a contact: normal along the distance field's gradient, from the user to the body.
// The contact solver solves them with the body's other contacts; the user gets no force.

#include <cstdint>
#include <map>
#include <vector>

#include "vrflow/camera/user_surface.hpp"
#include "vrflow/rigid/body.hpp"

namespace vrflow::rigid {

/// One contact of a body with a moving solid surface.
struct SurfaceContact {
  std::uint64_t body = 0;
  std::uint64_t surface = 0;  ///< the user's id
  Vec3 point{};               ///< on the body, world frame
  Vec3 normal{};              ///< unit, from the surface towards the body
  double distance = 0;        ///< negative when penetrating
  Vec3 surfaceVelocity{};     ///< the surface's velocity at the point (m/s)
};

/// Body-frame points on the surface of `shape`, at most about `spacing` apart on flat faces
/// (boxes; at most 8 per edge), where the user's field is sampled. Spheres and capsules give
/// their centres (the caller offsets them by the radius).
std::vector<Vec3> surfaceSamples(const msg::Shape& shape, double spacing);

/// Contacts of `body` (dynamic) with every user whose bounds it comes within `reach` of, in user
/// id order, then sample order; the body is sampled (surfaceSamples) `spacing` apart, only when a
/// user is near.
void userContacts(const Body& body, double spacing,
                  const std::map<std::uint64_t, const camera::UserSurface*>& users, double reach,
                  std::vector<SurfaceContact>& out);

}  // namespace vrflow::rigid
