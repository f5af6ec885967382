#pragma once

#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/fluid/solver.hpp"

// The fluid module's `state-file`: what the liquid and the bodies in it look like when the run
// ends, as JSON, for tests and for people checking an example (the rigid animator's state-file
// is the bodies' own side of the story).

namespace vrflow::fluid {

/// Everything the state file reports; filled by the module at the end of the run.
struct FinalState {
  double time = 0.0;              ///< simulated seconds
  unsigned long long steps = 0;   ///< steps taken
  FluidSettings settings;         ///< grid, for the surface level's columns
  double initialVolume = 0.0;     ///< liquidVolume() before the first step (m^3)
  double volume = 0.0;            ///< liquidVolume() at the end (m^3)
  double maxSpeed = 0.0;          ///< largest particle speed at the end (m/s)
  std::vector<float> particles;   ///< every particle's xyz at the end
  std::vector<RigidBody> bodies;  ///< the bodies of the last step
  std::vector<BodyForce> forces;  ///< their forces of the last step (same order, then nodes)
};

/// The free surface's height: per grid column (x, z) holding particles the highest particle's
/// y, then the median over those columns (robust to splashes and to columns under bodies).
double surfaceLevel(const FluidSettings& settings, const std::vector<float>& particles);

/// Writes `state` to `path` as JSON (format in nodes/fluid/README.md).
Status writeFinalState(const std::string& path, const FinalState& state);

}  // namespace vrflow::fluid
