#include "vrflow/rigid/world.hpp"

namespace vrflow::rigid {

Status RigidWorld::add(const std::vector<Body>& bodies) {
  for (const Body& body : bodies) {
    if (auto status = state_.addBody(body); !status) return status;
    if (auto status = solver_.setBody(*state_.find(body.id)); !status) return status;
  }
  return {};
}

std::vector<Change> RigidWorld::step(double dt) {
  for (const Body& b : state_.bodies()) {
    if (b.kinematic) continue;
    state_.applyForce(
        b.id, field_.forceOn({b.mass, b.position, b.linearVelocity, b.angularVelocity}, dt));
  }
  for (const auto& [id, event] : solver_.solve(dt)) state_.applyForce(id, event);
  auto changes = state_.step(dt);
  for (const Change& c : changes) {
    const Body& b = *state_.find(c.id);
    solver_.setState(b.id, b.position, b.orientation, b.linearVelocity, b.angularVelocity);
  }
  return changes;
}

}  // namespace vrflow::rigid
