#include "vrflow/rigid/contact_solver.hpp"

#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "vrflow/rigid/mesh.hpp"
#include "vrflow/rigid/user_contacts.hpp"

namespace vrflow::rigid {
namespace {

btVector3 toBt(const Vec3& v) {
  return {static_cast<btScalar>(v[0]), static_cast<btScalar>(v[1]), static_cast<btScalar>(v[2])};
}
Eigen::Vector3d fromBt(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}
btTransform transformOf(const Vec3& position, const Quat& q) {
  return btTransform(btQuaternion(static_cast<btScalar>(q[0]), static_cast<btScalar>(q[1]),
                                  static_cast<btScalar>(q[2]), static_cast<btScalar>(q[3])),
                     toBt(position));
}

// A deterministic tangent basis of a unit normal (as btPlaneSpace1).
void tangents(const Eigen::Vector3d& n, Eigen::Vector3d& t1, Eigen::Vector3d& t2) {
  if (std::abs(n[2]) > 0.7071067811865476) {
    const double a = n[1] * n[1] + n[2] * n[2];
    const double k = 1.0 / std::sqrt(a);
    t1 = {0, -n[2] * k, n[1] * k};
    t2 = {a * k, -n[0] * t1[2], n[0] * t1[1]};
  } else {
    const double a = n[0] * n[0] + n[1] * n[1];
    const double k = 1.0 / std::sqrt(a);
    t1 = {-n[1] * k, n[0] * k, 0};
    t2 = {-n[2] * t1[1], n[2] * t1[0], a * k};
  }
}

// The relative normal velocity after a bounce (the target of the normal row), for a contact
// whose gap `gap` (negative when they overlap) closes at relative normal velocity `vn` < 0 (this
// step's gravity included), under a relative normal acceleration `a` pulling the bodies together
// (gravity on one of them), with restitution `e`. The bounce gives back e^2 of the normal kinetic
// energy the pair has when it touches, measured with the quantity the integrator conserves in free
// flight (semi-implicit Euler keeps v^2/2 + a x - a v dt/2 exactly, x the gap, v its rate before
// the step): so the rebound reaches e^2 of the drop height whatever the step, where the plain -e vn
// bounced from where the last step left the body (up to |vn| dt above the surface) and rose that
// much higher (+15 % at dt = 0.01 for e = 0.5).
// With a = 0 it is -e vn.
double reboundVelocity(double e, double vn, double gap, double a, double dt) {
  const double before = vn + a * dt;  // the rate at the start of the step
  const double energy = 0.5 * before * before + a * gap - 0.5 * a * before * dt;
  // After the step the gap is gap + v dt: v^2/2 + a (gap + v dt) - a v dt / 2 = e^2 energy.
  const double c = a * gap - e * e * std::max(energy, 0.0);
  const double discriminant = 0.25 * a * a * dt * dt - 2.0 * c;
  if (discriminant <= 0) return 0.0;
  return std::max(-0.5 * a * dt + std::sqrt(discriminant), 0.0);
}

// Axis 0 is the normal (from b to a), 1 and 2 the friction tangents. For each axis the
// Jacobian's angular parts r x d and their images through the inverse inertia are precomputed.
struct Constraint {
  std::size_t a, b;
  Eigen::Vector3d ra, rb;
  std::array<Eigen::Vector3d, 3> dir, raxd, rbxd, ia, ib;
  std::array<double, 3> mass, acc;
  double target;
  double friction;  // the pair's coefficient
  Eigen::Vector3d accRoll;
  RowMatrix3d rollMass;    // inverse of (Ia^-1 + Ib^-1)
  bool rolls;              // a sphere or capsule is involved
  btManifoldPoint* point;  // Bullet's point (warm starting), null for a user contact
  Eigen::Vector3d surface = Eigen::Vector3d::Zero();  // b's surface velocity (users)
};

// A manifold in the order of its pair of ids.
struct PairRef {
  std::uint64_t lo, hi;
  int index;
};

}  // namespace

double combinedFriction(double a, double b, double fallback) {
  return std::sqrt((a < 0 ? fallback : a) * (b < 0 ? fallback : b));
}

double combinedRestitution(double a, double b, double fallback) {
  return std::max(a < 0 ? fallback : a, b < 0 ? fallback : b);
}

struct RigidContactSolver::Impl {
  struct Entry {
    Body body;
    std::vector<btScalar> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> meshData;
    std::unique_ptr<btCollisionShape> shape;
    std::unique_ptr<btCollisionObject> object;
    std::size_t dense = 0;  // index in the solve's arrays
  };

  Impl(double margin, double speculative) : margin_(margin), speculative_(speculative) {
    // No perturbation iterations: their extra points carry distances of the perturbed pose (off
    // by millimetres, which breaks speculative contacts); boxes and hulls get full manifolds from
    // polyhedral clipping instead, other pairs build theirs over steps (persistent manifolds).
    // One contact distance for every shape (gContactBreakingThreshold, set around each query),
    // not Bullet's default that shrinks it with the shape's size.
    dispatcher.setDispatcherFlags(0);
    // Moving triangle meshes (btGImpactMeshShape) against anything.
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
  }

  // Bullet's view of a triangle mesh body's vertices and triangles (kept in the entry).
  static btTriangleIndexVertexArray* meshInterface(Entry& e) {
    const msg::Shape& s = e.body.shape;
    e.vertices.clear();
    for (double v : s.vertices) e.vertices.push_back(static_cast<btScalar>(v));
    e.indices.assign(s.indices.begin(), s.indices.end());
    btIndexedMesh mesh;
    mesh.m_numTriangles = static_cast<int>(e.indices.size() / 3);
    mesh.m_triangleIndexBase = reinterpret_cast<const unsigned char*>(e.indices.data());
    mesh.m_triangleIndexStride = 3 * static_cast<int>(sizeof(int));
    mesh.m_numVertices = static_cast<int>(e.vertices.size() / 3);
    mesh.m_vertexBase = reinterpret_cast<const unsigned char*>(e.vertices.data());
    mesh.m_vertexStride = 3 * static_cast<int>(sizeof(btScalar));
    e.meshData = std::make_unique<btTriangleIndexVertexArray>();
    e.meshData->addIndexedMesh(mesh, PHY_INTEGER);
    return e.meshData.get();
  }
  ~Impl() {
    for (auto& [id, entry] : entries) world.removeCollisionObject(entry->object.get());
  }

  Status build(Entry& e) {
    const msg::Shape& s = e.body.shape;
    if (auto status = msg::validateShape(s); !status) return status;
    if (s.kind == msg::ShapeKind::ConvexHull) {
      auto hull = std::make_unique<btConvexHullShape>();
      for (std::size_t i = 0; i + 2 < s.vertices.size(); i += 3)
        hull->addPoint(btVector3(static_cast<btScalar>(s.vertices[i]),
                                 static_cast<btScalar>(s.vertices[i + 1]),
                                 static_cast<btScalar>(s.vertices[i + 2])),
                       false);
      hull->recalcLocalAabb();
      hull->setMargin(static_cast<btScalar>(margin_));
      hull->initializePolyhedralFeatures();
      e.shape = std::move(hull);
    } else if (s.kind == msg::ShapeKind::TriangleMesh && e.body.kinematic) {
      // Static, possibly open and concave: Bullet's BVH of triangles.
      e.shape = std::make_unique<btBvhTriangleMeshShape>(meshInterface(e), true);
    } else if (s.kind == msg::ShapeKind::TriangleMesh) {
      // Moving and possibly concave: GImpact (its triangles' tree is in the body frame, so a pose
      // change needs no update). The mesh must enclose its volume, which its inertia came from.
      if (auto closed = checkClosedMesh(s); !closed)
        return makeError("dynamic triangle mesh: " + closed.error().message);
      // GImpact tests the triangles whose boxes meet the other shape's, and grows those boxes by
      // the margin only: built with margin + speculative distance, they let the triangles (whose
      // margin is then set back) give speculative points as far as the other pairs do.
      auto mesh = std::make_unique<btGImpactMeshShape>(meshInterface(e));
      mesh->setMargin(static_cast<btScalar>(margin_ + speculative_));
      mesh->updateBound();
      for (int part = 0; part < mesh->getMeshPartCount(); ++part)
        mesh->getMeshPart(part)->getTrimeshPrimitiveManager()->m_margin =
            static_cast<btScalar>(margin_);
      e.shape = std::move(mesh);
    } else if (s.kind == msg::ShapeKind::Sphere) {
      e.shape = std::make_unique<btSphereShape>(static_cast<btScalar>(s.radius));
    } else if (s.kind == msg::ShapeKind::Box) {
      auto box = std::make_unique<btBoxShape>(toBt(s.halfExtents));
      const double smallest = std::min({s.halfExtents[0], s.halfExtents[1], s.halfExtents[2]});
      box->setMargin(static_cast<btScalar>(std::min(margin_, 0.2 * smallest)));
      box->initializePolyhedralFeatures();
      e.shape = std::move(box);
    } else {
      e.shape = std::make_unique<btCapsuleShape>(static_cast<btScalar>(s.radius),
                                                 static_cast<btScalar>(2.0 * s.halfHeight));
    }
    e.object = std::make_unique<btCollisionObject>();
    e.object->setCollisionShape(e.shape.get());
    e.object->setWorldTransform(transformOf(e.body.position, e.body.orientation));
    e.object->setUserPointer(&e);
    if (e.body.kinematic) {
      e.object->setCollisionFlags(btCollisionObject::CF_STATIC_OBJECT);
      world.addCollisionObject(e.object.get(), btBroadphaseProxy::StaticFilter,
                               btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
    } else {
      e.object->setCollisionFlags(0);
      world.addCollisionObject(e.object.get(), btBroadphaseProxy::DefaultFilter,
                               btBroadphaseProxy::AllFilter);
    }
    return {};
  }

  // GImpact (a moving mesh's pairs) makes a new manifold at every query: a flat face would get one
  // point per pair of triangles per step and nothing to warm start from. So the points of the last
  // solve are kept per pair and offered to the new manifold, where Bullet's own matching and
  // refresh keep those still in contact, as a persistent manifold does for the other pairs.
  static bool remadeEachQuery(const btPersistentManifold& m) {
    return m.getBody0()->getCollisionShape()->getShapeType() == GIMPACT_SHAPE_PROXYTYPE ||
           m.getBody1()->getCollisionShape()->getShapeType() == GIMPACT_SHAPE_PROXYTYPE;
  }
  static std::pair<std::uint64_t, std::uint64_t> idsOf(const btPersistentManifold& m) {
    return {static_cast<const Entry*>(m.getBody0()->getUserPointer())->body.id,
            static_cast<const Entry*>(m.getBody1()->getUserPointer())->body.id};
  }
  // After the query: the kept points join the new manifolds (a new point matching a kept one
  // takes its impulses), then every point is re-measured at the current poses.
  void restoreMeshPoints() {
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      btPersistentManifold& manifold = *dispatcher.getManifoldByIndexInternal(m);
      if (!remadeEachQuery(manifold)) continue;
      const auto it = meshPoints.find(idsOf(manifold));
      if (it == meshPoints.end()) continue;
      for (const btManifoldPoint& old : it->second) {
        const int match = manifold.getCacheEntry(old);
        if (match < 0) {
          manifold.addManifoldPoint(old);
          continue;
        }
        btManifoldPoint& fresh = manifold.getContactPoint(match);
        fresh.m_appliedImpulse = old.m_appliedImpulse;
        fresh.m_appliedImpulseLateral1 = old.m_appliedImpulseLateral1;
        fresh.m_appliedImpulseLateral2 = old.m_appliedImpulseLateral2;
      }
      manifold.refreshContactPoints(manifold.getBody0()->getWorldTransform(),
                                    manifold.getBody1()->getWorldTransform());
    }
    meshPoints.clear();
  }
  // After the solve (impulses written back): keep the moving meshes' points for the next query.
  void keepMeshPoints() {
    for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
      const btPersistentManifold& manifold = *dispatcher.getManifoldByIndexInternal(m);
      if (!remadeEachQuery(manifold) || manifold.getNumContacts() == 0) continue;
      auto& points = meshPoints[idsOf(manifold)];
      for (int i = 0; i < manifold.getNumContacts(); ++i)
        points.push_back(manifold.getContactPoint(i));
    }
  }

  double margin_;
  double speculative_;
  std::map<std::pair<std::uint64_t, std::uint64_t>, std::vector<btManifoldPoint>> meshPoints;
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &config};
  std::map<std::uint64_t, std::unique_ptr<Entry>> entries;
  // solve()'s dense per-body arrays, constraints and ordered manifolds, reused across steps.
  struct Scratch {
    std::vector<Entry*> bodies;
    std::vector<double> invMass;
    std::vector<RowMatrix3d> invInertia;
    std::vector<Eigen::Vector3d> v, w, linear, angular;
    std::vector<Constraint> constraints;
    std::vector<PairRef> pairs;
  } scratch;
};

RigidContactSolver::RigidContactSolver(ContactParams params)
    : impl_(std::make_unique<Impl>(params.margin, params.speculativeDistance)), params_(params) {}

RigidContactSolver::~RigidContactSolver() = default;

Status RigidContactSolver::setBody(const Body& body) {
  auto it = impl_->entries.find(body.id);
  if (it != impl_->entries.end() && it->second->body.shape == body.shape &&
      it->second->body.kinematic == body.kinematic) {
    it->second->body = body;
    it->second->object->setWorldTransform(transformOf(body.position, body.orientation));
    return {};
  }
  removeBody(body.id);
  auto entry = std::make_unique<Impl::Entry>();
  entry->body = body;
  if (auto status = impl_->build(*entry); !status)
    return makeError("rigid body " + std::to_string(body.id) + ": " + status.error().message);
  impl_->entries.emplace(body.id, std::move(entry));
  return {};
}

bool RigidContactSolver::setState(std::uint64_t id, const Vec3& position, const Quat& orientation,
                                  const Vec3& linearVelocity, const Vec3& angularVelocity) {
  const auto it = impl_->entries.find(id);
  if (it == impl_->entries.end()) return false;
  Body& b = it->second->body;
  b.position = position;
  b.orientation = orientation;
  b.linearVelocity = linearVelocity;
  b.angularVelocity = angularVelocity;
  it->second->object->setWorldTransform(transformOf(position, orientation));
  return true;
}

void RigidContactSolver::removeBody(std::uint64_t id) {
  const auto it = impl_->entries.find(id);
  if (it == impl_->entries.end()) return;
  impl_->world.removeCollisionObject(it->second->object.get());
  impl_->entries.erase(it);
  std::erase_if(impl_->meshPoints, [id](const auto& kept) {
    return kept.first.first == id || kept.first.second == id;
  });
}

bool RigidContactSolver::contains(std::uint64_t id) const {
  return impl_->entries.contains(id);
}
std::size_t RigidContactSolver::size() const {
  return impl_->entries.size();
}

std::vector<std::pair<std::uint64_t, msg::ForceEvent>> RigidContactSolver::solve(double dt) {
  contacts_.clear();
  std::vector<std::pair<std::uint64_t, msg::ForceEvent>> result;
  if (!(dt > 0)) return result;
  const ContactParams& p = params_;

  // Dense per-body arrays in id order; predicted velocities include the external acceleration.
  // The arrays live in impl_ and keep their capacity from step to step: allocated anew, the
  // constraints (about 0.6 KB each) took fresh pages from the kernel on every step.
  const std::size_t n = impl_->entries.size();
  auto& [bodies, invMass, invInertia, v, w, linear, angular, constraints, pairs] = impl_->scratch;
  bodies.clear();
  // Slot n stands for the captured users: infinite mass, at rest (their surface velocity is a
  // constraint's `surface`).
  invMass.assign(n + 1, 0.0);
  invInertia.assign(n + 1, RowMatrix3d::Zero());
  for (auto* vectors : {&v, &w, &linear, &angular}) vectors->assign(n + 1, Eigen::Vector3d::Zero());
  constraints.clear();
  for (auto& [id, entry] : impl_->entries) {
    const std::size_t k = bodies.size();
    entry->dense = k;
    bodies.push_back(entry.get());
    const Body& b = entry->body;
    invMass[k] = b.inverseMass();
    invInertia[k] = worldInverseInertia(b);
    v[k] = asEigen(b.linearVelocity);
    if (!b.kinematic) v[k] += asEigen(p.gravity) * dt;
    w[k] = asEigen(b.angularVelocity);
  }

  {
    // Bullet reads its contact distance from a global: set it for this query only.
    const btScalar saved = gContactBreakingThreshold;
    gContactBreakingThreshold = static_cast<btScalar>(p.speculativeDistance);
    impl_->world.performDiscreteCollisionDetection();
    gContactBreakingThreshold = saved;
  }
  impl_->restoreMeshPoints();

  auto velocityAlong = [&](const Constraint& c, int axis) {
    return v[c.a].dot(c.dir[axis]) + w[c.a].dot(c.raxd[axis]) - v[c.b].dot(c.dir[axis]) -
           w[c.b].dot(c.rbxd[axis]) - c.surface.dot(c.dir[axis]);
  };
  auto push = [&](const Constraint& c, int axis, double impulse) {
    v[c.a] += c.dir[axis] * (impulse * invMass[c.a]);
    w[c.a] += c.ia[axis] * impulse;
    v[c.b] -= c.dir[axis] * (impulse * invMass[c.b]);
    w[c.b] -= c.ib[axis] * impulse;
  };

  // The Jacobian of contact c at `middle` along `normal` (from b to a), its effective masses and
  // its target normal velocity (speculative below a gap, restitution, Baumgarte beyond slop, the
  // latter at most maxPushOut).
  auto setUp = [&](Constraint& c, const Eigen::Vector3d& middle, const Eigen::Vector3d& positionA,
                   const Eigen::Vector3d& positionB, const Eigen::Vector3d& normal, double distance,
                   bool kinematicA, bool kinematicB, double restitution,
                   double maxPushOut = std::numeric_limits<double>::infinity()) {
    c.ra = middle - positionA;
    c.rb = middle - positionB;
    c.dir[0] = normal;
    tangents(normal, c.dir[1], c.dir[2]);
    for (int axis = 0; axis < 3; ++axis) {
      c.raxd[axis] = c.ra.cross(c.dir[axis]);
      c.rbxd[axis] = c.rb.cross(c.dir[axis]);
      c.ia[axis] = invInertia[c.a] * c.raxd[axis];
      c.ib[axis] = invInertia[c.b] * c.rbxd[axis];
      const double k =
          invMass[c.a] + invMass[c.b] + c.ia[axis].dot(c.raxd[axis]) + c.ib[axis].dot(c.rbxd[axis]);
      c.mass[axis] = k > 0 ? 1.0 / k : 0.0;
    }
    const double vn = velocityAlong(c, 0);
    const bool bounce = vn < -p.restitutionThreshold;
    // Gravity's pull along the normal, bringing the pair together (a dynamic body falls).
    const Eigen::Vector3d g = asEigen(p.gravity);
    const double pull =
        -((kinematicA ? Eigen::Vector3d::Zero() : g) - (kinematicB ? Eigen::Vector3d::Zero() : g))
             .dot(normal);
    const auto rebound = [&](double gap) {
      return reboundVelocity(restitution, vn, gap, std::max(pull, 0.0), dt);
    };
    if (distance > 0) {
      // Speculative: approach allowed up to the gap; a bounce when the gap closes this step.
      c.target = -distance / dt;
      if (bounce && vn * dt < -distance) c.target = std::max(c.target, rebound(distance));
    } else {
      c.target =
          std::max(bounce ? rebound(distance) : 0.0,
                   std::min(p.baumgarte / dt * std::max(-distance - p.slop, 0.0), maxPushOut));
    }
  };

  // Manifolds in the order of their pair of ids (then Bullet's order, deterministic too).
  pairs.clear();
  const int manifolds = impl_->dispatcher.getNumManifolds();
  for (int m = 0; m < manifolds; ++m) {
    btPersistentManifold* manifold = impl_->dispatcher.getManifoldByIndexInternal(m);
    if (manifold->getNumContacts() == 0) continue;
    const auto* ea = static_cast<const Impl::Entry*>(manifold->getBody0()->getUserPointer());
    const auto* eb = static_cast<const Impl::Entry*>(manifold->getBody1()->getUserPointer());
    if (ea->body.kinematic && eb->body.kinematic) continue;
    pairs.push_back({std::min(ea->body.id, eb->body.id), std::max(ea->body.id, eb->body.id), m});
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const PairRef& x, const PairRef& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi < y.hi;
  });
  for (const PairRef& pair : pairs) {
    btPersistentManifold* manifold = impl_->dispatcher.getManifoldByIndexInternal(pair.index);
    const auto* ea = static_cast<const Impl::Entry*>(manifold->getBody0()->getUserPointer());
    const auto* eb = static_cast<const Impl::Entry*>(manifold->getBody1()->getUserPointer());
    for (int i = 0; i < manifold->getNumContacts(); ++i) {
      btManifoldPoint& pt = manifold->getContactPoint(i);
      Constraint c{};
      c.a = ea->dense;
      c.b = eb->dense;
      c.point = &pt;
      c.accRoll.setZero();
      Eigen::Vector3d normal = fromBt(pt.m_normalWorldOnB);
      const double len = normal.norm();
      if (!(len > 0)) continue;
      normal *= 1.0 / len;
      // One point for both bodies (the middle of the pair of closest points), so that the
      // contact's impulses are equal, opposite and collinear: momenta are conserved.
      const Eigen::Vector3d pa = fromBt(pt.getPositionWorldOnA());
      const Eigen::Vector3d pb = fromBt(pt.getPositionWorldOnB());
      const Eigen::Vector3d middle = (pa + pb) * 0.5;
      const double distance = pt.getDistance();
      setUp(c, middle, asEigen(ea->body.position), asEigen(eb->body.position), normal, distance,
            ea->body.kinematic, eb->body.kinematic,
            combinedRestitution(ea->body.restitution, eb->body.restitution, p.restitution));
      auto round = [](const Impl::Entry* e) {
        return e->body.shape.kind == msg::ShapeKind::Sphere ||
               e->body.shape.kind == msg::ShapeKind::Capsule;
      };
      c.rolls = p.rollingFriction > 0 && (round(ea) || round(eb));
      if (c.rolls) {
        c.rollMass = inverse(invInertia[c.a] + invInertia[c.b]);
      }
      c.friction = combinedFriction(ea->body.friction, eb->body.friction, p.friction);
      if (p.warmStart) {
        c.acc = {pt.m_appliedImpulse, pt.m_appliedImpulseLateral1, pt.m_appliedImpulseLateral2};
      }
      constraints.push_back(c);
      contacts_.push_back(
          {ea->body.id, eb->body.id, msg::toVec3(pb), msg::toVec3(normal), distance});
    }
  }

  // Contacts with the captured users (slot n: infinite mass; their surface moves), no warm start.
  if (!users_.empty()) {
    std::vector<SurfaceContact> surface;
    double spacing = users_.begin()->second->spacing;
    for (const auto& [id, user] : users_) spacing = std::min(spacing, user->spacing);
    for (const Impl::Entry* e : bodies) {
      if (e->body.kinematic) continue;
      userContacts(e->body, 2 * spacing, users_, p.speculativeDistance, surface);
    }
    for (const SurfaceContact& s : surface) {
      Constraint c{};
      c.a = impl_->entries.at(s.body)->dense;
      c.b = n;
      c.point = nullptr;
      c.accRoll.setZero();
      c.rolls = false;
      const Eigen::Vector3d normal = asEigen(s.normal);
      // The user's surface velocity, at most userSurfaceSpeed. Not only its normal part: the
      // field, smoothed over voxels, carries the motion of the user's surface near the sample
      // better than one sample's normal does (a hand pushing a crate along a table drives it
      // along the hand's motion through friction, not up along the tilted normals of its edge).
      c.surface = asEigen(s.surfaceVelocity);
      if (const double speed = c.surface.norm(); speed > p.userSurfaceSpeed)
        c.surface *= p.userSurfaceSpeed / speed;
      // The user has the interactor's friction and restitution (its own are unset: -1).
      const Body& body = bodies[c.a]->body;
      c.friction = combinedFriction(body.friction, -1, p.friction);
      setUp(c, asEigen(s.point), asEigen(body.position), asEigen(s.point), normal, s.distance,
            false, true, combinedRestitution(body.restitution, -1, p.restitution), p.userPushOut);
      constraints.push_back(c);
      contacts_.push_back({s.body, s.surface, s.point, s.normal, s.distance});
    }
  }

  for (const Constraint& c : constraints)
    for (int axis = 0; axis < 3; ++axis)
      if (c.acc[axis] != 0) push(c, axis, c.acc[axis]);

  for (int iteration = 0; iteration < p.iterations; ++iteration) {
    for (Constraint& c : constraints) {
      // Friction within the cone of the current normal impulse (box approximation).
      const double limit = c.friction * c.acc[0];
      for (int axis = 1; axis < 3; ++axis) {
        const double next =
            std::clamp(c.acc[axis] - c.mass[axis] * velocityAlong(c, axis), -limit, limit);
        const double delta = next - c.acc[axis];
        c.acc[axis] = next;
        if (delta != 0) push(c, axis, delta);
      }
      if (c.rolls && c.acc[0] > 0) {
        // Rolling and spinning resistance: an angular impulse against the relative rotation,
        // each component within rollingFriction * the normal impulse.
        const Eigen::Vector3d wrel = w[c.a] - w[c.b];
        const double rollLimit = p.rollingFriction * c.acc[0];
        const Eigen::Vector3d wanted = c.accRoll - c.rollMass * wrel;
        const Eigen::Vector3d next = wanted.cwiseMax(-rollLimit).cwiseMin(rollLimit);
        const Eigen::Vector3d delta = next - c.accRoll;
        c.accRoll = next;
        if (!delta.isZero(0.0)) {
          w[c.a] += invInertia[c.a] * delta;
          w[c.b] -= invInertia[c.b] * delta;
        }
      }
      const double next = std::max(c.acc[0] + c.mass[0] * (c.target - velocityAlong(c, 0)), 0.0);
      const double delta = next - c.acc[0];
      c.acc[0] = next;
      if (delta != 0) push(c, 0, delta);
    }
  }

  // The impulses each body received: the sums of the accumulated contact impulses.
  for (const Constraint& c : constraints) {
    if (c.point != nullptr) {
      c.point->m_appliedImpulse = static_cast<btScalar>(c.acc[0]);
      c.point->m_appliedImpulseLateral1 = static_cast<btScalar>(c.acc[1]);
      c.point->m_appliedImpulseLateral2 = static_cast<btScalar>(c.acc[2]);
    }
    const Eigen::Vector3d impulse =
        c.dir[0] * c.acc[0] + (c.dir[1] * c.acc[1] + c.dir[2] * c.acc[2]);
    linear[c.a] += impulse;
    linear[c.b] -= impulse;
    angular[c.a] += c.ra.cross(impulse) + c.accRoll;
    angular[c.b] -= c.rb.cross(impulse) + c.accRoll;
  }

  impl_->keepMeshPoints();

  for (std::size_t k = 0; k < n; ++k) {
    const Body& b = bodies[k]->body;
    if (b.kinematic) continue;
    if (linear[k].isZero(0.0) && angular[k].isZero(0.0)) continue;
    result.emplace_back(b.id,
                        msg::ForceEvent{msg::toVec3(linear[k] * (1.0 / dt)),
                                        msg::toVec3(angular[k] * (1.0 / dt)), b.position, dt});
  }
  return result;
}

}  // namespace vrflow::rigid
