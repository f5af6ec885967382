#pragma once
// Scenes of the user interaction tests: keyframe files that move the synthetic user's standing
// pose as a whole, and the application files that put it beside rigid bodies, a net or water.

#include <string>
#include <utility>
#include <vector>

#include "vrflow/message/values.hpp"

namespace vrflow::testing {

/// A keyframe file: the standing pose (vrflow::camera::standingPose) translated by each key's
/// shift (m) at its time (s), interpolated between keys, held before the first and after the last.
std::string userKeys(const std::vector<std::pair<double, msg::Vec3>>& keys);

/// The standing pose held until `start`, then translated by `shift` (m) until `end` (s), then held.
std::string shiftedUserKeys(double start, double end, const msg::Vec3& shift);

/// The node positions of a mass-spring net file (the animator's state-file), one xyz per node.
std::vector<msg::Vec3> netPositions(const std::string& netFile);

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
