#pragma once

#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/rigid/animator.hpp"
#include "vrflow/rigid/contact_solver.hpp"
#include "vrflow/rigid/force_field.hpp"

// The rigid network of figure 4 in one process (the "monolithic" form): one step is what one
// iteration of animator -> {force field, rigid interactor} -> animator does, with the same
// solver classes: the force field and the contact solver see the state after the previous step,
// their events are applied (field first, then contacts), then the animator integrates.

namespace vrflow::rigid {

class RigidWorld {
 public:
  RigidWorld(ForceField field, ContactParams params) : field_(std::move(field)), solver_(params) {}
  /// Adds bodies (ids must be unique).
  Status add(const std::vector<Body>& bodies);
  /// One step of dt; returns what the animator reports as changed.
  std::vector<Change> step(double dt);

  const RigidAnimatorState& state() const { return state_; }
  RigidAnimatorState& state() { return state_; }
  const RigidContactSolver& solver() const { return solver_; }
  /// The contact solver, to hand it captured users (RigidContactSolver::setUsers).
  RigidContactSolver& solver() { return solver_; }
  const ForceField& field() const { return field_; }

 private:
  ForceField field_;
  RigidAnimatorState state_;
  RigidContactSolver solver_;
};

}  // namespace vrflow::rigid
