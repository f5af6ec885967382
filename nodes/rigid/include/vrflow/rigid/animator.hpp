#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/rigid/body.hpp"

// The rigid animator's state and integrator, without any messaging: the `rigid-animator` module
// and the single-process ("monolithic") benchmark call the very same code.

namespace vrflow::rigid {

/// What a step changed for one body (an update chunk carries only those parameters).
struct Change {
  std::uint64_t id = 0;
  bool pose = false;      ///< position, orientation (and so bounds)
  bool velocity = false;  ///< linear and/or angular velocity
};

/// Sleeping: a dynamic body slower than `linear` and `angular` for `time` seconds is put to sleep
/// (velocities zeroed, one last change reported); it is then neither integrated nor reported
/// while the velocity change its impulses would cause per step stays below `wakeLinear` and
/// `wakeAngular` (its weight and its support cancel), and wakes otherwise (a blow, a lost
/// support). Sleeping bodies are what keeps a settled scene from sending every body every step.
struct SleepParams {
  bool enabled = true;
  double linear = 0.02;      ///< m/s
  double angular = 0.05;     ///< rad/s
  double time = 0.5;         ///< s
  double wakeLinear = 0.02;  ///< m/s per step
  double wakeAngular = 0.1;  ///< rad/s per step
};

class RigidAnimatorState {
 public:
  void setSleep(const SleepParams& sleep) { sleep_ = sleep; }
  const SleepParams& sleep() const { return sleep_; }
  bool asleep(std::uint64_t id) const;

  /// Adds a body; its id must be new (bodies are kept ordered by id).
  Status addBody(Body body);
  Status removeBody(std::uint64_t id);
  /// Bodies ordered by id.
  const std::vector<Body>& bodies() const { return bodies_; }
  const Body* find(std::uint64_t id) const;
  Body* find(std::uint64_t id);

  /// Accumulates a force event for the next step: impulse force * duration (duration <= 0 means
  /// "over the whole step") applied at `point` (so torque += (point - position) x force) plus the
  /// event's torque * duration. Events for unknown ids or kinematic bodies are ignored; returns
  /// false for an unknown id.
  bool applyForce(std::uint64_t id, const msg::ForceEvent& event);

  /// Integrates every dynamic body over dt (semi-implicit Euler): v += J / m; L = I_w w + H
  /// (world inertia I_w = R I_b R^T); the orientation advances with w = I_w^-1 L and is
  /// renormalised; w is recomputed from L with the new orientation (so a free body's angular
  /// momentum is conserved). Kinematic bodies move with their own velocities. Clears the
  /// accumulated impulses and returns the bodies whose state changed, ordered by id.
  std::vector<Change> step(double dt);

  double time() const { return time_; }

 private:
  struct Accumulator {
    Vec3 linear{};
    Vec3 angular{};
  };
  std::vector<Body> bodies_;
  std::vector<Accumulator> impulses_;    // force * duration of timed events
  std::vector<Accumulator> stepForces_;  // forces of events lasting the whole step
  struct Rest {
    double still = 0.0;  // seconds below the sleep thresholds
    bool asleep = false;
  };
  std::vector<Rest> rest_;
  SleepParams sleep_;
  std::map<std::uint64_t, std::size_t> index_;
  double time_ = 0.0;
  void reindex();
};

}  // namespace vrflow::rigid
