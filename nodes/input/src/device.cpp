// openDevice: the backends by their spec; the window backend.
#include "vrflow/input/device.hpp"

#include "vrflow/input/evdev_device.hpp"
#include "vrflow/input/keyframes.hpp"
#include "vrflow/input/plugin.hpp"
#include "vrflow/input/simulated_arm.hpp"

namespace vrflow::input {

Result<std::unique_ptr<Device>> openDevice(const std::string& spec, const DeviceOptions& options) {
  const auto colon = spec.find(':');
  const std::string scheme = spec.substr(0, colon);
  const std::string rest = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  if (scheme == "window" && colon == std::string::npos)
    return std::unique_ptr<Device>(new WindowDevice);
  if (colon != std::string::npos && !rest.empty()) {
    if (scheme == "script" || scheme == "arm") {
      auto track = KeyframeTrack::load(rest);
      if (!track) return track.error();
      if (scheme == "script") return std::unique_ptr<Device>(new ScriptedDevice(std::move(*track)));
      auto arm = SimulatedArm::create(std::move(*track), options);
      if (!arm) return arm.error();
      return std::unique_ptr<Device>(std::move(*arm));
    }
    if (scheme == "evdev") {
      auto device = EvdevDevice::open(rest, options);
      if (!device) return device.error();
      return std::unique_ptr<Device>(std::move(*device));
    }
    if (scheme == "plugin") return loadPluginDevice(rest);
  }
  return makeError("device '" + spec +
                   "': give script:FILE, evdev:/dev/input/eventN, window, arm:FILE or "
                   "plugin:LIBRARY.so[:ARGS]");
}

Result<DeviceSample> WindowDevice::sample(double time) {
  (void)time;
  return last_;
}

void WindowDevice::feed(const msg::PointerEvent& event) {
  last_.position = event.rayOrigin;
  last_.direction = event.rayDirection;
  last_.buttons = event.buttons;
}

}  // namespace vrflow::input
