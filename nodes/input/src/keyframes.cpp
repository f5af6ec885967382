// KeyframeTrack: the scripted device's file (format in keyframes.hpp and the README).
#include "vrflow/input/keyframes.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace vrflow::input {

namespace {

/// Reads the next field as a finite number; false at the end of the line.
bool readNumber(std::istringstream& fields, double& value, bool& bad) {
  std::string token;
  if (!(fields >> token)) return false;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  bad = end == token.c_str() || *end != '\0' || !std::isfinite(value);
  return true;
}

}  // namespace

Result<KeyframeTrack> KeyframeTrack::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return makeError(path + ": cannot read the keyframe file");
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), path);
}

Result<KeyframeTrack> KeyframeTrack::parse(const std::string& text, const std::string& name) {
  KeyframeTrack track;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<double> values;
    double value = 0;
    bool bad = false;
    while (readNumber(fields, value, bad)) {
      if (bad)
        return makeError(name + ":" + std::to_string(number) + ": field " +
                         std::to_string(values.size() + 1) + " is not a finite number");
      values.push_back(value);
    }
    if (values.empty()) continue;
    if (values.size() != 4 && values.size() != 5 && values.size() != 8)
      return makeError(name + ":" + std::to_string(number) +
                       ": a key is TIME X Y Z [BUTTONS [DX DY DZ]], got " +
                       std::to_string(values.size()) + " numbers");
    Keyframe key;
    key.time = values[0];
    key.position = {values[1], values[2], values[3]};
    if (values.size() >= 5) {
      if (values[4] < 0 || values[4] > 7 || values[4] != std::floor(values[4]))
        return makeError(name + ":" + std::to_string(number) +
                         ": BUTTONS must be a bit mask from 0 to 7 (1 left, 2 right, 4 middle)");
      key.buttons = static_cast<std::uint32_t>(values[4]);
    }
    if (values.size() == 8) {
      const double length = std::hypot(values[5], values[6], values[7]);
      if (!(length > 0))
        return makeError(name + ":" + std::to_string(number) + ": the direction is zero");
      key.direction = {values[5] / length, values[6] / length, values[7] / length};
    }
    if (!track.keys_.empty() && !(key.time > track.keys_.back().time))
      return makeError(name + ":" + std::to_string(number) + ": time " + std::to_string(key.time) +
                       " is not after the previous key's");
    track.keys_.push_back(key);
  }
  if (track.keys_.empty()) return makeError(name + ": no keyframe in the file");
  return track;
}

DeviceSample KeyframeTrack::at(double time) const {
  DeviceSample out;
  std::size_t next = 0;
  while (next < keys_.size() && keys_[next].time <= time) ++next;
  if (next == 0 || next == keys_.size()) {
    const Keyframe& key = next == 0 ? keys_.front() : keys_.back();
    out.position = key.position;
    out.direction = key.direction;
    out.buttons = key.buttons;
    return out;
  }
  const Keyframe& a = keys_[next - 1];
  const Keyframe& b = keys_[next];
  const double span = b.time - a.time;
  const double s = (time - a.time) / span;
  double length = 0;
  for (int k = 0; k < 3; ++k) {
    out.position[k] = a.position[k] + s * (b.position[k] - a.position[k]);
    out.velocity[k] = (b.position[k] - a.position[k]) / span;
    out.direction[k] = a.direction[k] + s * (b.direction[k] - a.direction[k]);
    length += out.direction[k] * out.direction[k];
  }
  length = std::sqrt(length);
  for (auto& d : out.direction) d = length > 0 ? d / length : 0.0;
  out.buttons = a.buttons;
  return out;
}

}  // namespace vrflow::input
