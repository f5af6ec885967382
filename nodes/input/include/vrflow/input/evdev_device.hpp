#pragma once

#include <memory>
#include <string>

#include "vrflow/input/device.hpp"

struct libevdev;

// The `evdev:/dev/input/eventN` backend: a Linux input device read through libevdev, without
// blocking. Relative axes (a SpaceMouse-class 6-DOF device, a mouse) move the tip by `scale`
// metres per count (REL_X/Y/Z) and turn it by `scale` radians per count (REL_RX/RY/RZ); absolute
// axes (a joystick) place it at origin + scale * the axis normalised to [-1, 1] (ABS_X/Y/Z).
// Buttons: BTN_LEFT/BTN_0/BTN_TRIGGER/BTN_SOUTH are left, BTN_RIGHT/BTN_1/BTN_THUMB/BTN_EAST
// right, BTN_MIDDLE/BTN_2/BTN_THUMB2/BTN_NORTH middle. Hot-plug: a node that is missing (with
// `hotplug`) or goes away is retried at every sample, and picked up when it (re)appears; a
// device that goes away is logged on stderr, and ends the module when `stopOnUnplug`.

namespace vrflow::input {

/// A Linux input device.
class EvdevDevice final : public Device {
 public:
  /// Opens `path`; a missing node is an error unless options.hotplug (then it is waited for).
  [[nodiscard]] static Result<std::unique_ptr<EvdevDevice>> open(const std::string& path,
                                                                 const DeviceOptions& options);
  ~EvdevDevice() override;
  EvdevDevice(const EvdevDevice&) = delete;
  EvdevDevice& operator=(const EvdevDevice&) = delete;
  /// Reads every pending event; present is false while the node is missing.
  Result<DeviceSample> sample(double time) override;
  /// The device's name (empty until opened).
  const std::string& name() const { return name_; }

 private:
  EvdevDevice(std::string path, const DeviceOptions& options);
  /// Opens the node; an error says why (errno's text).
  Status attach();
  void detach();
  void apply(unsigned type, unsigned code, int value);

  std::string path_;
  DeviceOptions options_;
  int fd_ = -1;
  libevdev* device_ = nullptr;
  std::string name_;
  DeviceSample state_;
  double lastTime_ = 0.0;
  msg::Vec3 lastPosition_{};
};

}  // namespace vrflow::input
