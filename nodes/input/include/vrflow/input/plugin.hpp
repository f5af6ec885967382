#pragma once

#include <memory>
#include <string>

#include "vrflow/input/device.hpp"

// The `plugin:LIBRARY.so[:ARGS]` backend: a device (a haptic SDK's arm) in a shared library
// that the module dlopen()s. The library implements vrflow::input::Device and exports
//   extern "C" vrflow::input::Device* vrflow_input_create_device(const char* args, char* error,
//                                                                 std::size_t errorSize);
// returning a device made with `new`, or null after writing why into `error`; the module
// deletes the device before it closes the library. The library must be built against the same
// vrflow headers (kDeviceAbiVersion) and the same C++ standard library.

namespace vrflow::input {

/// Bumped whenever Device's virtual functions change; a plugin exports
/// `extern "C" int vrflow_input_device_abi()` returning the version it was built with.
inline constexpr int kDeviceAbiVersion = 1;

/// The signatures a plugin exports.
using CreateDeviceFunction = Device* (*)(const char* args, char* error, std::size_t errorSize);
using DeviceAbiFunction = int (*)();

/// Loads `LIBRARY[:ARGS]`; errors name the library and say what is missing.
[[nodiscard]] Result<std::unique_ptr<Device>> loadPluginDevice(const std::string& spec);

}  // namespace vrflow::input
