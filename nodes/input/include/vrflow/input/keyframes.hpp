#pragma once

#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/input/device.hpp"

// A scripted device: a keyframe file, one key per line,
//   TIME X Y Z [BUTTONS [DX DY DZ]]      # comment
// TIME in seconds, strictly increasing; X Y Z the tip (m); BUTTONS a bit mask (1 left, 2 right,
// 4 middle; default 0); DX DY DZ a pointing direction (normalised on load; default none).
// Positions and directions are interpolated linearly, buttons are those of the last key at or
// before the time; before the first key the first holds, after the last the last.

namespace vrflow::input {

/// One keyframe.
struct Keyframe {
  double time = 0.0;
  msg::Vec3 position{};
  std::uint32_t buttons = 0;
  msg::Vec3 direction{};
};

/// A keyframe track (nodes/input/README.md, "Keyframe files").
class KeyframeTrack {
 public:
  /// Reads a file; errors name FILE:LINE.
  [[nodiscard]] static Result<KeyframeTrack> load(const std::string& path);
  /// Parses text; `name` is the file name the errors give.
  [[nodiscard]] static Result<KeyframeTrack> parse(const std::string& text,
                                                   const std::string& name);
  /// The interpolated state at `time` (velocity: the slope of the segment).
  DeviceSample at(double time) const;
  const std::vector<Keyframe>& keys() const { return keys_; }

 private:
  std::vector<Keyframe> keys_;
};

/// The `script:FILE` backend.
class ScriptedDevice final : public Device {
 public:
  explicit ScriptedDevice(KeyframeTrack track) : track_(std::move(track)) {}
  Result<DeviceSample> sample(double time) override { return track_.at(time); }

 private:
  KeyframeTrack track_;
};

}  // namespace vrflow::input
