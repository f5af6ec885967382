// loadPluginDevice: a device in a shared library (interface in plugin.hpp).
#include "vrflow/input/plugin.hpp"

#include <dlfcn.h>

#include <array>

namespace vrflow::input {

namespace {

/// Forwards to the plugin's device and closes the library after deleting it.
class PluginDevice final : public Device {
 public:
  PluginDevice(void* library, Device* device) : library_(library), device_(device) {}
  ~PluginDevice() override {
    device_.reset();
    dlclose(library_);
  }
  PluginDevice(const PluginDevice&) = delete;
  PluginDevice& operator=(const PluginDevice&) = delete;
  Result<DeviceSample> sample(double time) override { return device_->sample(time); }
  void render(const msg::Vec3& force, double dt) override { device_->render(force, dt); }
  void feed(const msg::PointerEvent& event) override { device_->feed(event); }
  bool haptic() const override { return device_->haptic(); }

 private:
  void* library_;
  std::unique_ptr<Device> device_;
};

}  // namespace

Result<std::unique_ptr<Device>> loadPluginDevice(const std::string& spec) {
  const auto colon = spec.find(':');
  const std::string path = spec.substr(0, colon);
  const std::string args = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  void* library = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library) return makeError("plugin:" + path + ": cannot load it (" + dlerror() + ")");
  auto fail = [&](const std::string& why) -> Error {
    dlclose(library);
    return makeError("plugin:" + path + ": " + why);
  };
  const auto abi = reinterpret_cast<DeviceAbiFunction>(dlsym(library, "vrflow_input_device_abi"));
  const auto create =
      reinterpret_cast<CreateDeviceFunction>(dlsym(library, "vrflow_input_create_device"));
  if (!abi || !create)
    return fail("exports no vrflow_input_device_abi / vrflow_input_create_device");
  if (abi() != kDeviceAbiVersion)
    return fail("built for device interface " + std::to_string(abi()) + ", this is " +
                std::to_string(kDeviceAbiVersion));
  std::array<char, 512> error{};
  Device* device = create(args.c_str(), error.data(), error.size());
  if (!device) return fail(error[0] ? error.data() : "the device could not be created");
  return std::unique_ptr<Device>(new PluginDevice(library, device));
}

}  // namespace vrflow::input
