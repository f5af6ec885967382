#pragma once

#include <memory>

#include "vrflow/input/keyframes.hpp"

// The `arm:FILE` backend: a simulated haptic arm, to test the feedback loop without hardware.
// The hand is a mass M with the device's physical damping b, held by the user through a spring
// (stiffness k_u) to a target that follows the keyframes of FILE:
//   M dv/dt = k_u (target(t) - x) - b v + F_rendered,
// integrated by semi-implicit Euler in `armSubsteps` sub-steps per render() call, the rendered
// force held over the call (zero-order hold, as a real device's amplifier does). It keeps its
// energy books: the work of the user's spring, of the rendered force, and the damping loss.

namespace vrflow::input {

/// A simulated haptic arm (mass-spring-damper hand).
class SimulatedArm final : public Device {
 public:
  /// An arm whose hand starts at rest at the track's first key. Errors name the bad option.
  [[nodiscard]] static Result<std::unique_ptr<SimulatedArm>> create(KeyframeTrack track,
                                                                    const DeviceOptions& options);
  /// The hand's state; also the time render() integrates from.
  Result<DeviceSample> sample(double time) override;
  /// Integrates the hand over dt with `force` on it.
  void render(const msg::Vec3& force, double dt) override;
  bool haptic() const override { return true; }

  /// Energy books (J): kinetic energy of the hand; work done on it by the user's spring and by
  /// the rendered force; energy its damping took.
  double kineticEnergy() const;
  double userWork() const { return userWork_; }
  double renderedWork() const { return renderedWork_; }
  double dampingLoss() const { return dampingLoss_; }

 private:
  SimulatedArm(KeyframeTrack track, const DeviceOptions& options);
  KeyframeTrack track_;
  DeviceOptions options_;
  double time_ = 0.0;
  msg::Vec3 position_{};
  msg::Vec3 velocity_{};
  double userWork_ = 0.0;
  double renderedWork_ = 0.0;
  double dampingLoss_ = 0.0;
};

}  // namespace vrflow::input
