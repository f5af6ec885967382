// KeyframeTrack: the synthetic user's motion file (format in nodes/camera/README.md).
#include <fstream>
#include <sstream>

#include "vrflow/camera/synthetic_user.hpp"

namespace vrflow::camera {

namespace {

struct PartialKey {
  UserPose pose;
  std::array<bool, kUserJoints.size()> given{};
  int firstLine = 0;
};

}  // namespace

Result<KeyframeTrack> KeyframeTrack::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return makeError(path + ": cannot read the keyframe file");
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), path);
}

Result<KeyframeTrack> KeyframeTrack::parse(const std::string& text, const std::string& name) {
  std::map<double, PartialKey> partial;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    double t = 0;
    std::string joint;
    cv::Vec3d p;
    if (!(fields >> t)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      return makeError(name + ":" + std::to_string(number) +
                       ": expected 'TIME JOINT X Y Z' (seconds, joint name, metres)");
    }
    std::string extra;
    if (!(fields >> joint >> p[0] >> p[1] >> p[2]) || (fields >> extra))
      return makeError(name + ":" + std::to_string(number) +
                       ": expected 'TIME JOINT X Y Z' (seconds, joint name, metres)");
    if (!std::isfinite(t) || !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      return makeError(name + ":" + std::to_string(number) + ": a NaN or infinite number");
    std::size_t index = 0;
    while (index < kUserJoints.size() && joint != kUserJoints[index]) ++index;
    if (index == kUserJoints.size())
      return makeError(name + ":" + std::to_string(number) + ": unknown joint '" + joint +
                       "' (head, neck, pelvis, shoulder_l/r, elbow_l/r, wrist_l/r, hand_l/r)");
    PartialKey& key = partial[t];
    if (key.firstLine == 0) key.firstLine = number;
    if (key.given[index])
      return makeError(name + ":" + std::to_string(number) + ": joint '" + joint +
                       "' given twice at time " + std::to_string(t));
    key.given[index] = true;
    key.pose[index] = p;
  }
  if (partial.empty()) return makeError(name + ": no keyframe (expected lines 'TIME JOINT X Y Z')");
  KeyframeTrack track;
  for (const auto& [t, key] : partial) {
    for (std::size_t i = 0; i < kUserJoints.size(); ++i)
      if (!key.given[i])
        return makeError(name + ":" + std::to_string(key.firstLine) + ": the key at time " +
                         std::to_string(t) + " lacks joint '" + kUserJoints[i] + "'");
    track.keys_[t] = key.pose;
  }
  return track;
}

UserPose KeyframeTrack::poseAt(double t) const {
  auto after = keys_.lower_bound(t);
  if (after == keys_.begin()) return after->second;
  if (after == keys_.end()) return keys_.rbegin()->second;
  const auto before = std::prev(after);
  const double w = (t - before->first) / (after->first - before->first);
  UserPose pose;
  for (std::size_t i = 0; i < pose.size(); ++i)
    pose[i] = (1 - w) * before->second[i] + w * after->second[i];
  return pose;
}

}  // namespace vrflow::camera
