// SimulatedArm: the mass-spring-damper hand behind the `arm:FILE` backend.
#include "vrflow/input/simulated_arm.hpp"

#include <cmath>

namespace vrflow::input {

Result<std::unique_ptr<SimulatedArm>> SimulatedArm::create(KeyframeTrack track,
                                                           const DeviceOptions& options) {
  if (!(options.armMass > 0) || !std::isfinite(options.armMass))
    return makeError("arm-mass must be a positive number of kg");
  if (!(options.armDamping >= 0) || !std::isfinite(options.armDamping))
    return makeError("arm-damping must be a finite number >= 0 (N s/m)");
  if (!(options.armStiffness >= 0) || !std::isfinite(options.armStiffness))
    return makeError("arm-stiffness must be a finite number >= 0 (N/m)");
  if (options.armSubsteps < 1) return makeError("arm sub-steps must be at least 1");
  return std::unique_ptr<SimulatedArm>(new SimulatedArm(std::move(track), options));
}

SimulatedArm::SimulatedArm(KeyframeTrack track, const DeviceOptions& options)
    : track_(std::move(track)), options_(options) {
  position_ = track_.at(track_.keys().front().time).position;
}

Result<DeviceSample> SimulatedArm::sample(double time) {
  time_ = time;
  DeviceSample out;
  out.position = position_;
  out.velocity = velocity_;
  out.buttons = track_.at(time).buttons;
  return out;
}

void SimulatedArm::render(const msg::Vec3& force, double dt) {
  // Each sub-step holds its forces (the user's spring and the damping at its start, the
  // rendered force over the whole call) and moves the hand exactly under them, so the work of
  // each force, F . dx, sums exactly to the kinetic energy change.
  const double h = dt / options_.armSubsteps;
  for (int s = 0; s < options_.armSubsteps; ++s) {
    const auto target = track_.at(time_).position;
    for (int k = 0; k < 3; ++k) {
      const double user = options_.armStiffness * (target[k] - position_[k]);
      const double damping = -options_.armDamping * velocity_[k];
      const double acceleration = (user + damping + force[k]) / options_.armMass;
      const double step = h * velocity_[k] + 0.5 * h * h * acceleration;
      position_[k] += step;
      velocity_[k] += h * acceleration;
      userWork_ += user * step;
      renderedWork_ += force[k] * step;
      dampingLoss_ -= damping * step;
    }
    time_ += h;
  }
}

double SimulatedArm::kineticEnergy() const {
  double sum = 0;
  for (const double v : velocity_) sum += v * v;
  return 0.5 * options_.armMass * sum;
}

}  // namespace vrflow::input
