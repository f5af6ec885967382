#pragma once

#include <memory>
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

}  // namespace vrflow::input
