// HapticTool: virtual coupling between a device and a simulated tool (model in coupling.hpp).
#include "vrflow/input/coupling.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace vrflow::input {

double maxPassiveStiffness(const CouplingParams& params) {
  return std::min(2.0 * params.damping / params.period,
                  4.0 * params.toolMass / (params.physicsPeriod * params.physicsPeriod));
}

Status checkCoupling(const CouplingParams& params) {
  auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
  if (!(params.toolMass > 0) || !std::isfinite(params.toolMass))
    return makeError("tool-mass must be a positive number of kg");
  if (!(params.period > 0) || !std::isfinite(params.period))
    return makeError("dt must be a positive number of seconds");
  if (!(params.physicsPeriod >= params.period) || !std::isfinite(params.physicsPeriod))
    return makeError("physics-dt must be a number of seconds no shorter than dt");
  if (!(params.damping >= 0) || !std::isfinite(params.damping))
    return makeError("damping must be a finite number >= 0 (N s/m)");
  const double bound = maxPassiveStiffness(params);
  if (!(params.stiffness > 0) || !(params.stiffness <= bound))
    return makeError("stiffness " + number(params.stiffness) +
                     " N/m is outside the passive range (0, min(2 c / T, 4 m / dt^2)] = (0, " +
                     number(bound) + "] for damping c = " + number(params.damping) +
                     " N s/m, dt T = " + number(params.period) +
                     " s, tool-mass m = " + number(params.toolMass) +
                     " kg, physics-dt dt = " + number(params.physicsPeriod) + " s");
  return {};
}

HapticTool::HapticTool(const CouplingParams& params, const msg::Vec3& start)
    : params_(params), position_(start) {}

msg::Vec3 HapticTool::step(const DeviceSample& device, const msg::Vec3& contact) {
  msg::Vec3 feedback{};
  for (int k = 0; k < 3; ++k) {
    coupling_[k] = params_.stiffness * (device.position[k] - position_[k]) +
                   params_.damping * (device.velocity[k] - velocity_[k]);
    // The forces are held over the tick and the tool moves exactly under them (its kinetic
    // energy changes by exactly their work, F . dx).
    const double acceleration = (coupling_[k] + contact[k]) / params_.toolMass + params_.gravity[k];
    position_[k] +=
        params_.period * velocity_[k] + 0.5 * params_.period * params_.period * acceleration;
    velocity_[k] += params_.period * acceleration;
    feedback[k] = -coupling_[k];
  }
  return feedback;
}

double HapticTool::energy(const msg::Vec3& device) const {
  double kinetic = 0, stretch = 0;
  for (int k = 0; k < 3; ++k) {
    kinetic += velocity_[k] * velocity_[k];
    stretch += (device[k] - position_[k]) * (device[k] - position_[k]);
  }
  return 0.5 * params_.toolMass * kinetic + 0.5 * params_.stiffness * stretch;
}

}  // namespace vrflow::input
