#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "vrflow/base/result.hpp"
#include "vrflow/message/input_events.hpp"
#include "vrflow/message/values.hpp"

// A device that enters the simulation (the paper's section 3.7): something with a pose and
// buttons, sampled once per module iteration, and, for haptic devices, a force rendered back to
// the hand. Backends (openDevice's spec): a scripted keyframe file, Linux input devices through
// libevdev, the on-screen viewer's pointer events, a simulated haptic arm, and a plugin.

namespace vrflow::input {

/// What a device reports at one sample. Units: metres, seconds, world frame.
struct DeviceSample {
  msg::Vec3 position{};               ///< the device's tip (a ray's origin)
  msg::Quat orientation{0, 0, 0, 1};  ///< x, y, z, w
  msg::Vec3 velocity{};               ///< of the tip (m/s); zero when the backend cannot tell
  msg::Vec3 direction{};              ///< unit pointing direction; 0 0 0: a point, not a ray
  std::uint32_t buttons = 0;          ///< msg::buttonBit()s held
  bool present = true;                ///< false while an unplugged device is waited for
};

/// A device backend. One instance per module; not thread-safe.
class Device {
 public:
  virtual ~Device() = default;
  /// The device's state at simulation time `time` (s). An error ends the module (a script
  /// that cannot be read, a device that went away when asked to stop then).
  virtual Result<DeviceSample> sample(double time) = 0;
  /// Renders `force` (N, world) on the user's hand for the next `dt` seconds (haptic devices;
  /// others ignore it).
  virtual void render(const msg::Vec3& force, double dt) {
    (void)force;
    (void)dt;
  }
  /// Feeds an input event from a window (the `window` backend; others ignore it).
  virtual void feed(const msg::PointerEvent& event) { (void)event; }
  /// True when render() reaches a hand (a haptic device).
  virtual bool haptic() const { return false; }
};

/// Settings of the backends that need more than their spec (defaults as in the manifest).
struct DeviceOptions {
  double scale = 0.001;       ///< evdev: metres per relative count, or per unit of a full abs range
  msg::Vec3 origin{};         ///< evdev: where the device's zero sits in the world
  bool hotplug = true;        ///< evdev: a missing node is waited for (picked up when it appears)
  bool stopOnUnplug = false;  ///< evdev: a device that goes away ends the module
  double armMass = 0.5;       ///< arm: the hand's mass (kg)
  double armDamping = 4.0;    ///< arm: the hand's physical damping b (N s/m)
  double armStiffness = 400.0;  ///< arm: the user's grip, a spring to the scripted target (N/m)
  int armSubsteps = 10;         ///< arm: integration sub-steps per render() call
};

/// Opens a device from its spec: `script:FILE` (keyframes), `evdev:/dev/input/eventN`,
/// `window` (pointer events fed by the module), `arm:FILE` (simulated haptic arm whose hand
/// follows the keyframes of FILE) or `plugin:LIBRARY.so[:ARGS]`. Errors name the spec.
[[nodiscard]] Result<std::unique_ptr<Device>> openDevice(const std::string& spec,
                                                         const DeviceOptions& options = {});

/// The `window` backend: the last pointer event's ray and buttons.
class WindowDevice final : public Device {
 public:
  Result<DeviceSample> sample(double time) override;
  void feed(const msg::PointerEvent& event) override;

 private:
  DeviceSample last_{};
};

}  // namespace vrflow::input
