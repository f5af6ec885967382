#include "rigid_solve.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "vrflow/massspring/solver.hpp"
#include "vrflow/message/eigen.hpp"

namespace vrflow::massspring::detail {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using msg::asEigen;

/// A rigid's velocity and inverse mass and world inverse inertia while the solve runs.
struct BodyState {
  Vector3d v = Vector3d::Zero(), w = Vector3d::Zero();
  double invMass = 0;
  Matrix3d invInertia = Matrix3d::Zero();
};

/// A net's node velocities and inverse masses while the solve runs (pinned: 0).
struct NetState {
  const Net* net = nullptr;
  std::vector<double> v;
  std::vector<double> invMass;
};

/// A spring in the solve: its nodes, the inverse of their summed inverse masses, its stiffness
/// terms and its accumulated impulses (along b minus a: positive pushes the ends apart).
struct SpringRow {
  std::size_t a = 0, b = 0;
  double invW = 0;  ///< 1 / (wa + wb)
  double restLength = 0;
  double startLength = 0;  ///< at the start of the step
  double stiffness = 0, damping = 0;
  double limit = 0;  ///< largest length, 0 for none
  double soft = 0, hard = 0;
};

BodyState bodyState(const RigidBody& body) {
  BodyState s;
  s.v = asEigen(body.linearVelocity);
  s.w = asEigen(body.angularVelocity);
  if (!(body.mass > 0) || !std::isfinite(body.mass)) return s;
  s.invMass = 1.0 / body.mass;
  const auto properties = msg::massProperties(body.shape, body.mass);
  const Matrix3d local = asEigen(properties.inertia);
  const Matrix3d rotation = asEigen(body.orientation).toRotationMatrix();
  const Eigen::FullPivLU<Matrix3d> lu(local);
  if (lu.isInvertible()) s.invInertia = rotation * lu.inverse() * rotation.transpose();
  return s;
}

std::vector<SpringRow> springRows(const Net& net, const std::vector<double>& invMass) {
  std::vector<SpringRow> rows;
  rows.reserve(net.springs.size());
  for (const auto& s : net.springs) {
    const double wSum = invMass[s.a] + invMass[s.b];
    if (wSum == 0 || (s.stiffness == 0 && s.damping == 0 && s.maxStretch <= 0)) continue;
    SpringRow row;
    row.a = s.a;
    row.b = s.b;
    row.invW = 1.0 / wSum;
    row.restLength = s.restLength;
    row.startLength = (msg::asVector3(&net.positions[3 * std::size_t{s.b}]) -
                       msg::asVector3(&net.positions[3 * std::size_t{s.a}]))
                          .norm();
    row.stiffness = s.stiffness;
    row.damping = s.damping;
    row.limit = s.maxStretch > 0 ? s.maxStretch * s.restLength : 0.0;
    rows.push_back(row);
  }
  return rows;
}

/// The spring's vector (b minus a) at the end of the step, if the nodes kept their velocities.
Vector3d predicted(const NetState& state, const SpringRow& row, double dt) {
  const auto& x = state.net->positions;
  const auto& v = state.v;
  return msg::asVector3(&x[3 * row.b]) + dt * msg::asVector3(&v[3 * row.b]) -
         msg::asVector3(&x[3 * row.a]) - dt * msg::asVector3(&v[3 * row.a]);
}

/// Adds impulse `lambda` along u to node b and its opposite to node a.
void applySpring(NetState& state, const SpringRow& row, const Vector3d& u, double lambda) {
  msg::asVector3(&state.v[3 * row.b]) += u * (state.invMass[row.b] * lambda);
  msg::asVector3(&state.v[3 * row.a]) -= u * (state.invMass[row.a] * lambda);
}

/// One Gauss-Seidel update of a spring, at the positions the step would end at (so that a taut
/// net resists a transverse push through its geometry, as the animator's projection does):
/// the implicit spring force over the step, then the maximum length.
void solveSpring(NetState& state, SpringRow& row, double dt) {
  Vector3d d = predicted(state, row, dt);
  double length = d.norm();
  if (length < 1e-12) return;
  Vector3d u = d / length;
  // Spring: impulse P = -dt k C - c (C - C0) at the end-of-step extension C (implicit Euler).
  if (row.stiffness > 0 || row.damping > 0) {
    const double c = length - row.restLength, c0 = row.startLength - row.restLength;
    const double target = -(dt * row.stiffness + row.damping) * c + row.damping * c0;
    const double delta =
        (target - row.soft) / (1.0 + (dt * dt * row.stiffness + dt * row.damping) / row.invW);
    row.soft += delta;
    applySpring(state, row, u, delta);
    // The nodes' velocities moved by delta (wa + wb) along u: the end-of-step vector by dt times
    // that (no need to read the nodes again).
    d += u * (dt * delta / row.invW);
    length = d.norm();
    if (length < 1e-12) return;
    u = d / length;
  }
  if (row.limit > 0) {
    // The pull (<= 0) that brings the end-of-step length to the limit.
    const double next = std::min(0.0, row.hard - (length - row.limit) * row.invW / dt);
    applySpring(state, row, u, next - row.hard);
    row.hard = next;
  }
}

}  // namespace

ContactImpulses solveRigidNetContacts(const std::map<std::uint64_t, Net>& nets,
                                      const std::map<std::uint64_t, RigidBody>& rigids,
                                      const std::map<std::uint64_t, Eigen::Vector3d>& drift,
                                      const std::vector<RigidNetContact>& contacts,
                                      const ContactParams& p) {
  std::vector<double> impulses(contacts.size(), 0.0);
  if (contacts.empty()) return {};
  // Only the rigids and nets that take part, in id order.
  std::map<std::uint64_t, BodyState> bodies;
  std::map<std::uint64_t, NetState> states;
  for (const auto& c : contacts) {
    if (!bodies.count(c.rigidId)) {
      auto body = bodyState(rigids.at(c.rigidId));
      if (const auto found = drift.find(c.rigidId); found != drift.end()) body.v += found->second;
      bodies.emplace(c.rigidId, body);
    }
    if (!states.count(c.netId)) {
      const Net& net = nets.at(c.netId);
      NetState s{&net, net.velocities, std::vector<double>(net.nodeCount(), 0.0)};
      for (std::size_t i = 0; i < net.nodeCount(); ++i)
        s.invMass[i] = net.pinned[i] ? 0.0 : 1.0 / net.masses[i];
      states.emplace(c.netId, std::move(s));
    }
  }
  std::map<std::uint64_t, std::vector<SpringRow>> springs;
  for (const auto& [id, s] : states) springs[id] = springRows(*s.net, s.invMass);

  // Per contact: the effective mass and the lowest allowed relative normal velocity.
  std::vector<double> mass(contacts.size(), 0.0), target(contacts.size(), 0.0);
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto& c = contacts[i];
    const auto& body = bodies.at(c.rigidId);
    const auto& net = states.at(c.netId);
    double k = body.invMass;
    const Vector3d rn = c.r.cross(c.normal);
    k += rn.dot(body.invInertia * rn);
    for (int j = 0; j < c.count; ++j) k += c.w[j] * c.w[j] * net.invMass[c.nodes[j]];
    mass[i] = k > 0 ? 1.0 / k : 0.0;
    target[i] = c.distance > p.thickness
                    ? -(c.distance - p.thickness) / p.dt
                    : std::min(p.beta * (p.thickness - c.distance) / p.dt, kMaxPushSpeed);
  }

  for (int iteration = 0; iteration < p.iterations; ++iteration) {
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      if (mass[i] == 0) continue;
      const auto& c = contacts[i];
      auto& body = bodies.at(c.rigidId);
      auto& net = states.at(c.netId);
      Vector3d point = Vector3d::Zero();
      for (int j = 0; j < c.count; ++j) point += c.w[j] * msg::asVector3(&net.v[3 * c.nodes[j]]);
      const double vn = (point - body.v - body.w.cross(c.r)).dot(c.normal);
      const double next = std::max(0.0, impulses[i] + (target[i] - vn) * mass[i]);
      const double delta = next - impulses[i];
      impulses[i] = next;
      const Vector3d push = c.normal * delta;
      for (int j = 0; j < c.count; ++j)
        msg::asVector3(&net.v[3 * c.nodes[j]]) += push * (c.w[j] * net.invMass[c.nodes[j]]);
      body.v -= push * body.invMass;
      body.w -= body.invInertia * c.r.cross(push);
    }
    // The nets' springs, forward then backward on alternate sweeps.
    for (auto& [id, rows] : springs) {
      auto& net = states.at(id);
      const std::size_t count = rows.size();
      for (std::size_t index = 0; index < count; ++index)
        solveSpring(net, rows[iteration % 2 == 0 ? index : count - 1 - index], p.dt);
    }
  }
  // A taut net is locked: with its rows and columns straight at their limits, a transverse push
  // meets limits whose directions it barely changes, so these sweeps (at the end-of-step
  // positions) let the nodes give way while the animator's projection cannot meet the limits and
  // cuts the motion short (the net stays put). So the nets' motion is taken only as far along as
  // every limit holds (feasibleFraction, as the animator backs off), and on a net with limits
  // the rigids take the rest: further impulses against its nodes moving so, as if infinitely
  // heavy. Those do not go to the net: its limits hand them on to its pins. (On a net without
  // limits every impulse acts on both sides: momentum is exchanged exactly.)
  std::set<std::uint64_t> limited;
  for (auto& [id, state] : states) {
    std::vector<double> end = state.net->positions;
    for (std::size_t k = 0; k < end.size(); ++k) end[k] += p.dt * state.v[k];
    const double t = std::clamp(feasibleFraction(*state.net, state.net->positions, end), 0.0, 1.0);
    for (auto& v : state.v) v *= t;
    if (std::any_of(state.net->springs.begin(), state.net->springs.end(),
                    [](const Spring& spring) { return spring.maxStretch > 0; }))
      limited.insert(id);
  }
  std::vector<double> rigidMass(contacts.size(), 0.0), extra(contacts.size(), 0.0);
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto& c = contacts[i];
    const auto& body = bodies.at(c.rigidId);
    const Vector3d rn = c.r.cross(c.normal);
    const double k = body.invMass + rn.dot(body.invInertia * rn);
    rigidMass[i] = k > 0 ? 1.0 / k : 0.0;
  }
  for (int iteration = 0; iteration < p.iterations; ++iteration) {
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      if (rigidMass[i] == 0 || !limited.count(contacts[i].netId)) continue;
      const auto& c = contacts[i];
      auto& body = bodies.at(c.rigidId);
      const auto& net = states.at(c.netId);
      Vector3d point = Vector3d::Zero();
      for (int j = 0; j < c.count; ++j) point += c.w[j] * msg::asVector3(&net.v[3 * c.nodes[j]]);
      const double vn = (point - body.v - body.w.cross(c.r)).dot(c.normal);
      const double next = std::max(0.0, extra[i] + (target[i] - vn) * rigidMass[i]);
      const Vector3d push = c.normal * (next - extra[i]);
      extra[i] = next;
      body.v -= push * body.invMass;
      body.w -= body.invInertia * c.r.cross(push);
    }
  }
  return {std::move(impulses), std::move(extra)};
}

}  // namespace vrflow::massspring::detail
