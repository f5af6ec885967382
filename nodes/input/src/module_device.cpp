// openModuleDevice and feedPointerEvents: the input modules' shared start.
#include "vrflow/input/module_device.hpp"

#include <cstdio>

#include "vrflow/module/start.hpp"

namespace vrflow::input {

std::unique_ptr<Device> openModuleDevice(const Module& module, const std::string& program,
                                         bool haptic) {
  const auto& params = module.params();
  auto fail = [&](const char* name, const std::string& why) {
    std::fprintf(stderr, "%s: parameter '%s' of module '%s': %s\n", program.c_str(), name,
                 module.id().c_str(), why.c_str());
    return std::unique_ptr<Device>();
  };
  DeviceOptions options;
  options.scale = params.getFloat("scale");
  options.origin = params.getVec3("origin");
  options.hotplug = params.getBool("hotplug");
  const std::string unplug = params.getString("on-unplug");
  if (unplug != "keep" && unplug != "stop")
    return fail("on-unplug", "'" + unplug + "' is neither keep nor stop");
  options.stopOnUnplug = unplug == "stop";
  if (haptic) {
    options.armMass = params.getFloat("arm-mass");
    options.armDamping = params.getFloat("arm-damping");
    options.armStiffness = params.getFloat("arm-stiffness");
  }
  std::string spec = params.getString("device");
  // `script` and `arm` alone take their file from `keyframes` (a file parameter: resolved
  // beside the application file and checked before the run starts).
  if (spec == "script" || spec == "arm") {
    const std::string keyframes = params.getString("keyframes");
    if (keyframes.empty())
      return fail("keyframes", "device '" + spec + "' needs a keyframe file: set keyframes");
    spec += ":" + keyframes;
  }
  auto device = openDevice(spec, options);
  if (!device) return fail("device", device.error().message);
  if (haptic && !(*device)->haptic())
    return fail("device", "'" + spec + "' renders no force: give arm:FILE or plugin:LIBRARY.so");
  return std::move(*device);
}

int feedPointerEvents(Device& device, const Message& message) {
  if (!message.valid()) return 0;
  int count = 0;
  for (const auto chunk : message.view()) {
    const auto event = chunk.asEvent();
    if (!event || event->kind() != msg::kPointerEventKind) continue;
    if (const auto pointer = msg::pointerEvent(*event)) {
      device.feed(*pointer);
      ++count;
    }
  }
  return count;
}

std::optional<DeviceModule> startDeviceModule(Module& module, const std::string& program) {
  const InputPort& events = module.addInput("device");
  const OutputPort& objects = module.addOutput("objects");
  if (!initOrReport(module, program)) return std::nullopt;
  auto device = openModuleDevice(module, program);
  if (!device) return std::nullopt;
  return DeviceModule{events, objects, std::move(device)};
}

std::optional<DeviceSample> nextSample(const Module& module, const InputPort* events,
                                       Device& device, const std::string& program, double time) {
  if (events) feedPointerEvents(device, module.get(*events));
  auto sample = device.sample(time);
  if (!sample) {
    std::fprintf(stderr, "%s: %s\n", program.c_str(), sample.error().message.c_str());
    return std::nullopt;
  }
  return *sample;
}

}  // namespace vrflow::input
