#pragma once

#include <memory>
#include <optional>
#include <string>

#include "vrflow/input/device.hpp"
#include "vrflow/module/module.hpp"

// What the input modules share: the device from their parameters, and the window events of
// their `device` input port.

namespace vrflow::input {

/// Opens the device the module's parameters name (`device`, `keyframes` for `script` and `arm`
/// given alone, `scale`, `origin`, `hotplug`,
/// `on-unplug` and, where declared, `arm-mass`, `arm-damping`, `arm-stiffness`). On error prints
/// "PROGRAM: parameter 'NAME' of module 'ID': why" and returns null (exit with status 2).
std::unique_ptr<Device> openModuleDevice(const Module& module, const std::string& program,
                                         bool haptic = false);

/// Feeds the pointer events of `message` (if valid) to the device; returns how many.
int feedPointerEvents(Device& device, const Message& message);

/// The ports and the device of a module that only publishes a device (pointer, head): a
/// `device` input for window events, an `objects` output.
struct DeviceModule {
  const InputPort& events;
  const OutputPort& objects;
  std::unique_ptr<Device> device;
};

/// Declares the ports, joins the run and opens the device; nullopt (after printing why) when it
/// cannot: exit with status 2.
std::optional<DeviceModule> startDeviceModule(Module& module, const std::string& program);

/// Feeds this iteration's window events from `events` (when given) and samples the device at
/// `time`; nullopt after printing "PROGRAM: why" when the device fails: exit with status 1.
std::optional<DeviceSample> nextSample(const Module& module, const InputPort* events,
                                       Device& device, const std::string& program, double time);

}  // namespace vrflow::input
