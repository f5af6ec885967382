#pragma once

#include <span>
#include <vector>

#include "vrflow/massspring/net.hpp"
#include "vrflow/massspring/user_collider.hpp"

// Explicit integration of a net with internal sub-steps.
//
// The choice: one outer step of length dt is cut into `substeps` sub-steps of h = dt / substeps.
// External forces (what interactors sent for this outer step, and gravity) are held constant over
// the sub-steps; the net's own spring forces are recomputed at every sub-step from the current
// positions and velocities (when `internalSprings` is set). Each sub-step is symplectic
// (semi-implicit) Euler: v += h f / m, then x += h v, for free nodes; pinned nodes never move.
// After each sub-step the maximum-stretch constraint is projected (see enforceMaxStretch),
// warm-started from the last sub-step's multipliers (StepOptions::warmStart). With captured users
// (user_collider.hpp), each sub-step's integration is followed by their collider first: the
// nodes go out of the users, then the maximum stretch is projected.

namespace vrflow::massspring {

struct StepOptions {
  double dt = 0.01;               ///< outer step (s)
  int substeps = 10;              ///< sub-steps per outer step (>= 1)
  bool internalSprings = true;    ///< evaluate the net's springs at every sub-step
  msg::Vec3 gravity{0, 0, 0};     ///< acceleration applied to every free node (m/s^2)
  int constraintIterations = 50;  ///< most Gauss-Seidel sweeps of the max-stretch projection
  /// The max-stretch projection's multipliers at the end of the last sub-step, one per spring
  /// (step() keeps them here to warm-start the next sub-step, and starts from zeros when their
  /// count is not the net's spring count). Not an option: state carried from step to step, so
  /// keep one StepOptions per net. A stale value costs sweeps, never correctness.
  mutable std::vector<double> warmStart;
};
Status validateStepOptions(const StepOptions& options);

/// Adds the spring forces of `net` (Hooke + damping along the spring) to `forces` (xyz per node).
void addSpringForces(const Net& net, std::span<double> forces);
/// Same for a subset of springs (used by the spring interactor and by tests).
void addSpringForces(const Net& net, std::span<const Spring> springs, std::span<double> forces);

/// Projects every spring with maxStretch > 0 back to length <= maxStretch * restLength (moving
/// its free ends, inverse-mass weighted, pinned nodes immovable) by projected Gauss-Seidel on the
/// inequalities: each spring's correction is accumulated in its entry of `multipliers`
/// (mass-weighted length, kept >= 0, so a spring that is no longer needed lets go), which is first
/// applied again (warm start) and holds the result on return; empty: start from zeros. Sweeps
/// run until no correction changes a length by more than 0.5e-9 of its limit or `maxIterations`
/// sweeps ran. The position change of each node is added to its velocity divided by `h`. If a
/// spring is still beyond its limit and `feasible` (positions that met every limit, e.g. those
/// at the start of the sub-step) is given, the nodes of those springs go back to `feasible`, and
/// round after round the nodes of the springs that this stretched beyond their limits, until
/// every limit holds: only that part of the net has its motion of the sub-step cut short.
/// Returns the largest length / (maxStretch * restLength) left (0 if no spring has a limit).
double enforceMaxStretch(Net& net, double h, int maxIterations,
                         std::span<const double> feasible = {}, std::span<double> multipliers = {});

/// The largest fraction t in [0, 1] such that every limited spring holds (length <= maxStretch *
/// restLength, less 0.5e-9 of it) at from + t (to - from), the nodes moving on straight lines;
/// 0 when a spring that `to` stretches beyond its limit is not inside it at `from` already.
/// `from` and `to` hold xyz per node.
double feasibleFraction(const Net& net, std::span<const double> from, std::span<const double> to);

/// The fastest angular frequency (rad/s) of the net's springs about its present state: the square
/// root of the largest eigenvalue of M^-1 K over the free nodes, K the springs' tangent stiffness
/// (k u u^T along each spring, plus k (1 - L0 / L) across it while it is stretched), damping left
/// out. Symplectic Euler integrates those springs stably with a step h only while omega h < 2
/// (damping lowers that bound further). Estimated by `iterations` power iterations from a fixed
/// start vector: the result (the largest Rayleigh quotient met) never exceeds the true value and
/// approaches it from below. 0 when no free node has a spring with stiffness.
double fastestSpringFrequency(const Net& net, int iterations = 300);

/// Advances the net by one outer step. `externalForces` holds xyz per node (or is empty);
/// `users`, when given, are collided with after every sub-step's integration (collideWithUsers).
/// Returns the largest constraint ratio left (see enforceMaxStretch), 0 if no spring has a limit.
double step(Net& net, std::span<const double> externalForces, const StepOptions& options,
            const UserColliders* users = nullptr);

/// Energies: kinetic, elastic (sum of k/2 (L - L0)^2) and gravitational (-sum m g.x).
double kineticEnergy(const Net& net);
double elasticEnergy(const Net& net);
double gravityEnergy(const Net& net, const msg::Vec3& gravity);
/// Largest length / restLength over the springs.
double maxStretchRatio(const Net& net);
/// Largest length / (maxStretch * restLength) over the springs that have a limit (0 if none).
double maxConstraintRatio(const Net& net);

}  // namespace vrflow::massspring
