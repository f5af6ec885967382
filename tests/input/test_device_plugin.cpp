// A device plugin for the plugin backend's test: a hand held at the position its arguments give
// ("X Y Z"), which moves by the forces rendered on it (1 kg, no damping) — built as a shared
// library the test loads through `plugin:LIBRARY:ARGS`, as a haptic SDK's wrapper would be.
#include <cstdio>
#include <sstream>

#include "vrflow/input/plugin.hpp"

namespace {

class TestHand final : public vrflow::input::Device {
 public:
  explicit TestHand(const vrflow::msg::Vec3& at) { state_.position = at; }
  vrflow::Result<vrflow::input::DeviceSample> sample(double time) override {
    (void)time;
    return state_;
  }
  void render(const vrflow::msg::Vec3& force, double dt) override {
    for (int k = 0; k < 3; ++k) {
      state_.velocity[k] += dt * force[k];
      state_.position[k] += dt * state_.velocity[k];
    }
  }
  bool haptic() const override { return true; }

 private:
  vrflow::input::DeviceSample state_;
};

}  // namespace

extern "C" int vrflow_input_device_abi() {
  return vrflow::input::kDeviceAbiVersion;
}

extern "C" vrflow::input::Device* vrflow_input_create_device(const char* args, char* error,
                                                             std::size_t errorSize) {
  std::istringstream in(args);
  vrflow::msg::Vec3 at{};
  if (!(in >> at[0] >> at[1] >> at[2])) {
    std::snprintf(error, errorSize, "arguments '%s' are not X Y Z", args);
    return nullptr;
  }
  return new TestHand(at);
}
