#pragma once
// Keyframe text for the synthetic user (the format of KeyframeTrack::load), shared by the tests.
#include <sstream>
#include <string>

#include "vrflow/camera/synthetic_user.hpp"

namespace vrflow::camera {

/// The lines of one key: every joint of `pose` at time `t`.
inline std::string keyText(double t, const UserPose& pose) {
  std::ostringstream out;
  for (std::size_t i = 0; i < pose.size(); ++i)
    out << t << ' ' << kUserJoints[i] << ' ' << pose[i][0] << ' ' << pose[i][1] << ' ' << pose[i][2]
        << '\n';
  return out.str();
}

}  // namespace vrflow::camera
