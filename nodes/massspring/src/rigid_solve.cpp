#include "rigid_solve.hpp"

#include <algorithm>
#include <cmath>

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

/// A spring in the solve: its nodes (first indices into the flat arrays), their inverse masses,
/// the constants of its updates (built once per solve, not per sweep) and its accumulated impulses
/// (along b minus a: positive pushes the ends apart).
struct SpringRow {
  std::size_t a = 0, b = 0;  ///< 3 * node
  double wa = 0, wb = 0;     ///< the nodes' inverse masses
  double restLength = 0;
  double stiff = 0;      ///< dt k + c: the impulse per metre of end-of-step extension
  double pullBack = 0;   ///< c (C0): the damping's share of the start-of-step extension C0
  double gain = 0;       ///< 1 / (1 + (dt^2 k + dt c) (wa + wb)): the implicit update's factor
  double travel = 0;     ///< dt (wa + wb): the end-of-step length change per unit impulse
  double limit = 0;      ///< largest length, 0 for none
  double limitGain = 0;  ///< 1 / (dt (wa + wb)): the impulse per metre beyond the limit
  bool elastic = false;  ///< has stiffness or damping
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

std::vector<SpringRow> springRows(const Net& net, const std::vector<double>& invMass, double dt) {
  std::vector<SpringRow> rows;
  rows.reserve(net.springs.size());
  for (const auto& s : net.springs) {
    const double wSum = invMass[s.a] + invMass[s.b];
    if (wSum == 0 || (s.stiffness == 0 && s.damping == 0 && s.maxStretch <= 0)) continue;
    SpringRow row;
    row.a = 3 * std::size_t{s.a};
    row.b = 3 * std::size_t{s.b};
    row.wa = invMass[s.a];
    row.wb = invMass[s.b];
    row.restLength = s.restLength;
    const double startLength =
        (msg::asVector3(&net.positions[row.b]) - msg::asVector3(&net.positions[row.a])).norm();
    row.elastic = s.stiffness > 0 || s.damping > 0;
    row.stiff = dt * s.stiffness + s.damping;
    row.pullBack = s.damping * (startLength - s.restLength);
    row.gain = 1.0 / (1.0 + (dt * dt * s.stiffness + dt * s.damping) * wSum);
    row.travel = dt * wSum;
    row.limit = s.maxStretch > 0 ? s.maxStretch * s.restLength : 0.0;
    row.limitGain = 1.0 / row.travel;
    rows.push_back(row);
  }
  return rows;
}

/// Adds impulse `lambda` along (u0, u1, u2) to node b and its opposite to node a.
void applySpring(double* v, const SpringRow& row, double u0, double u1, double u2, double lambda) {
  const double pb = row.wb * lambda, pa = row.wa * lambda;
  v[row.b] += u0 * pb;
  v[row.b + 1] += u1 * pb;
  v[row.b + 2] += u2 * pb;
  v[row.a] -= u0 * pa;
  v[row.a + 1] -= u1 * pa;
  v[row.a + 2] -= u2 * pa;
}

/// One Gauss-Seidel update of a spring, at the positions the step would end at (so that a taut
/// net resists a transverse push through its geometry, as the animator's projection does):
/// the implicit spring force over the step, then the maximum length. Written out on the flat
/// arrays with the row's constants: the sweeps are this function (no division but one per
/// length).
void solveSpring(const double* x, double* v, SpringRow& row, double dt) {
  const std::size_t a = row.a, b = row.b;
  // The spring's vector (b minus a) at the end of the step, if the nodes kept their velocities.
  double d0 = x[b] + dt * v[b] - x[a] - dt * v[a];
  double d1 = x[b + 1] + dt * v[b + 1] - x[a + 1] - dt * v[a + 1];
  double d2 = x[b + 2] + dt * v[b + 2] - x[a + 2] - dt * v[a + 2];
  // Spring: impulse P = -dt k C - c (C - C0) at the end-of-step extension C (implicit Euler).
  if (row.elastic) {
    const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    if (length < 1e-12) return;
    const double inverse = 1.0 / length;
    const double u0 = d0 * inverse, u1 = d1 * inverse, u2 = d2 * inverse;
    const double target = -row.stiff * (length - row.restLength) + row.pullBack;
    const double delta = (target - row.soft) * row.gain;
    row.soft += delta;
    applySpring(v, row, u0, u1, u2, delta);
    // The nodes' velocities moved by delta (wa + wb) along u: the end-of-step vector by dt times
    // that (no need to read the nodes again).
    const double moved = delta * row.travel;
    d0 += u0 * moved;
    d1 += u1 * moved;
    d2 += u2 * moved;
  }
  // The maximum length: a spring within it that pulls nothing is left alone (most of them, most
  // sweeps: no square root, no division).
  if (row.limit <= 0) return;
  const double squared = d0 * d0 + d1 * d1 + d2 * d2;
  if (row.hard == 0 && squared <= row.limit * row.limit) return;
  const double length = std::sqrt(squared);
  if (length < 1e-12) return;
  const double inverse = 1.0 / length;
  // The pull (<= 0) that brings the end-of-step length to the limit.
  const double next = std::min(0.0, row.hard - (length - row.limit) * row.limitGain);
  applySpring(v, row, d0 * inverse, d1 * inverse, d2 * inverse, next - row.hard);
  row.hard = next;
}

}  // namespace

ContactImpulses solveRigidNetContacts(const std::map<std::uint64_t, Net>& nets,
                                      const std::map<std::uint64_t, RigidBody>& rigids,
                                      const std::map<std::uint64_t, Eigen::Vector3d>& drift,
                                      const std::vector<RigidNetContact>& contacts,
                                      const ContactParams& p) {
  std::vector<double> impulses(contacts.size(), 0.0);
  if (contacts.empty()) return {};
  // Only the rigids and nets that take part, in id order, in arrays; each contact holds the
  // indices of its rigid and net (no map lookup in the sweeps).
  std::map<std::uint64_t, std::size_t> bodyIndex, netIndex;
  for (const auto& c : contacts) {
    bodyIndex.emplace(c.rigidId, 0);
    netIndex.emplace(c.netId, 0);
  }
  std::vector<BodyState> bodies;
  bodies.reserve(bodyIndex.size());
  for (auto& [id, index] : bodyIndex) {
    index = bodies.size();
    auto body = bodyState(rigids.at(id));
    if (const auto found = drift.find(id); found != drift.end()) body.v += found->second;
    bodies.push_back(body);
  }
  std::vector<NetState> states;
  std::vector<std::vector<SpringRow>> springs;
  std::vector<bool> limited;  // the net has maximum-stretch limits
  states.reserve(netIndex.size());
  for (auto& [id, index] : netIndex) {
    index = states.size();
    const Net& net = nets.at(id);
    NetState s{&net, net.velocities, std::vector<double>(net.nodeCount(), 0.0)};
    for (std::size_t i = 0; i < net.nodeCount(); ++i)
      s.invMass[i] = net.pinned[i] ? 0.0 : 1.0 / net.masses[i];
    springs.push_back(springRows(net, s.invMass, p.dt));
    limited.push_back(std::any_of(net.springs.begin(), net.springs.end(),
                                  [](const Spring& spring) { return spring.maxStretch > 0; }));
    states.push_back(std::move(s));
  }
  std::vector<std::size_t> bodyOf(contacts.size()), netOf(contacts.size());
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    bodyOf[i] = bodyIndex.at(contacts[i].rigidId);
    netOf[i] = netIndex.at(contacts[i].netId);
  }

  // Per contact: the effective mass, the lowest allowed relative normal velocity, and the
  // rigid's angular response to a unit push (world inverse inertia times r x n).
  std::vector<double> mass(contacts.size(), 0.0), target(contacts.size(), 0.0);
  std::vector<Vector3d> rn(contacts.size()), turn(contacts.size());
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto& c = contacts[i];
    const auto& body = bodies[bodyOf[i]];
    const auto& net = states[netOf[i]];
    double k = body.invMass;
    rn[i] = c.r.cross(c.normal);
    turn[i] = body.invInertia * rn[i];
    k += rn[i].dot(turn[i]);
    for (int j = 0; j < c.count; ++j) k += c.w[j] * c.w[j] * net.invMass[c.nodes[j]];
    mass[i] = k > 0 ? 1.0 / k : 0.0;
    target[i] = c.distance > p.thickness
                    ? -(c.distance - p.thickness) / p.dt
                    : std::min(p.beta * (p.thickness - c.distance) / p.dt, kMaxPushSpeed);
  }
  // The relative normal velocity of contact i (node side minus rigid side).
  auto normalSpeed = [&](std::size_t i) {
    const auto& c = contacts[i];
    const auto& body = bodies[bodyOf[i]];
    const auto& v = states[netOf[i]].v;
    double vn = 0;
    for (int j = 0; j < c.count; ++j)
      vn += c.w[j] * msg::asVector3(&v[3 * c.nodes[j]]).dot(c.normal);
    return vn - body.v.dot(c.normal) - body.w.dot(rn[i]);
  };
  // A push of `delta` (N s) along the normal on the rigid's side only.
  auto pushRigid = [&](std::size_t i, double delta) {
    auto& body = bodies[bodyOf[i]];
    body.v -= contacts[i].normal * (delta * body.invMass);
    body.w -= turn[i] * delta;
  };

  for (int iteration = 0; iteration < p.iterations; ++iteration) {
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      if (mass[i] == 0) continue;
      const auto& c = contacts[i];
      auto& net = states[netOf[i]];
      const double next = std::max(0.0, impulses[i] + (target[i] - normalSpeed(i)) * mass[i]);
      const double delta = next - impulses[i];
      impulses[i] = next;
      for (int j = 0; j < c.count; ++j)
        msg::asVector3(&net.v[3 * c.nodes[j]]) +=
            c.normal * (delta * c.w[j] * net.invMass[c.nodes[j]]);
      pushRigid(i, delta);
    }
    // The nets' springs, forward then backward on alternate sweeps.
    for (std::size_t n = 0; n < states.size(); ++n) {
      const double* x = states[n].net->positions.data();
      double* v = states[n].v.data();
      auto& rows = springs[n];
      const std::size_t count = rows.size();
      if (iteration % 2 == 0) {
        for (std::size_t index = 0; index < count; ++index) solveSpring(x, v, rows[index], p.dt);
      } else {
        for (std::size_t index = count; index-- > 0;) solveSpring(x, v, rows[index], p.dt);
      }
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
  for (auto& state : states) {
    std::vector<double> end = state.net->positions;
    for (std::size_t k = 0; k < end.size(); ++k) end[k] += p.dt * state.v[k];
    const double t = std::clamp(feasibleFraction(*state.net, state.net->positions, end), 0.0, 1.0);
    for (auto& v : state.v) v *= t;
  }
  std::vector<double> rigidMass(contacts.size(), 0.0), extra(contacts.size(), 0.0);
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const double k = bodies[bodyOf[i]].invMass + rn[i].dot(turn[i]);
    rigidMass[i] = k > 0 ? 1.0 / k : 0.0;
  }
  for (int iteration = 0; iteration < p.iterations; ++iteration) {
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      if (rigidMass[i] == 0 || !limited[netOf[i]]) continue;
      const double next = std::max(0.0, extra[i] + (target[i] - normalSpeed(i)) * rigidMass[i]);
      pushRigid(i, next - extra[i]);
      extra[i] = next;
    }
  }
  return {std::move(impulses), std::move(extra)};
}

}  // namespace vrflow::massspring::detail
