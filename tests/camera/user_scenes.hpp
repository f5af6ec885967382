#pragma once
// Scenes of the user interaction tests: keyframe files that move the synthetic user's standing
// pose as a whole, and the application files that put it beside rigid bodies, a net or water.

#include <string>

#include "vrflow/message/values.hpp"

namespace vrflow::testing {

/// A keyframe file: the standing pose (vrflow::camera::standingPose) held until `start`, then
/// translated by `shift` (m) until `end` (s), then held.
std::string shiftedUserKeys(double start, double end, const msg::Vec3& shift);

/// The modules and connections that bring the user into an application: `truth` (camera
/// user-truth on `keys`, `cells` voxels per edge of the cube of `edge` m at `origin`) feeding
/// `user` (camera user-animator), whose objects go to every interactor named in `to`
/// (space-separated "module.port" targets).
struct UserModules {
  std::string modules;
  std::string connections;
};
UserModules userModules(const std::string& keys, int cells, const msg::Vec3& origin, double edge,
                        const std::string& to);

}  // namespace vrflow::testing
