#pragma once

#include "vrflow/base/result.hpp"
#include "vrflow/input/device.hpp"

// Virtual coupling (Colgate, Stanley & Brown 1995) for the haptic module: the device's proxy
// and a simulated tool joined by a spring-damper. Each haptic tick (period T):
//   F = k d + c (v_device - v_tool),   d = x_device - x_tool   (force on the tool),
// F and the contact force F_c are held over the tick and the tool moves exactly under them
// (x += T v + T^2 a / 2, v += T a, a = (F + F_c) / m), and -F goes back to the device as the
// feedback force, held over the tick too (zero-order hold).
// Passivity: over a tick the coupling gives the two bodies -F . dd and its spring's energy
// changes by k d . dd + k |dd|^2 / 2, so it generates k |dd|^2 / 2 - c v_rel . dd: the held
// spring gains (Colgate & Schenkel's sampled-spring term), the damper loses. With dd ~ T v_rel,
// the coupling is passive when k T^2 / 2 <= c T, i.e.
//   k <= k_max = 2 c / T,
// whatever the tool touches and however the device moves (a device's own damping b only adds
// margin: 2 (b + c) / T when the tool is held still, Colgate's virtual wall).
// The contacts come at the physics step dt (10 ms), held over it: they can only follow the tool
// on its spring when that mode is resolved by dt, sqrt(k / m) dt < 2 (semi-implicit Euler's
// limit), so also k <= 4 m / dt^2. The range is 0 < k <= min(2 c / T, 4 m / dt^2).

namespace vrflow::input {

/// Settings of the coupling and the tool (defaults as in the haptic module's manifest).
struct CouplingParams {
  double stiffness = 2000.0;    ///< k (N/m)
  double damping = 2.0;         ///< c (N s/m)
  double toolMass = 0.2;        ///< m (kg)
  double period = 0.001;        ///< T (s)
  double physicsPeriod = 0.01;  ///< dt of the contacts (s)
  msg::Vec3 gravity{};          ///< acceleration of the tool (the hand carries its weight: 0)
};

/// The stiffness range's top, min(2 c / T, 4 m / dt^2).
double maxPassiveStiffness(const CouplingParams& params);

/// Checks the settings; errors name the haptic module's parameter and the bound.
Status checkCoupling(const CouplingParams& params);

/// The simulated tool on its coupling.
class HapticTool {
 public:
  HapticTool(const CouplingParams& params, const msg::Vec3& start);
  /// One tick: the coupling force from `device`, `contact` (N) on the tool, integration.
  /// Returns the force on the device (the feedback, -F).
  msg::Vec3 step(const DeviceSample& device, const msg::Vec3& contact);
  const msg::Vec3& position() const { return position_; }
  const msg::Vec3& velocity() const { return velocity_; }
  /// The coupling force on the tool during the last step.
  const msg::Vec3& couplingForce() const { return coupling_; }
  /// Kinetic energy of the tool plus the coupling spring's energy for a device at `device` (J).
  double energy(const msg::Vec3& device) const;

 private:
  CouplingParams params_;
  msg::Vec3 position_{};
  msg::Vec3 velocity_{};
  msg::Vec3 coupling_{};
};

}  // namespace vrflow::input
