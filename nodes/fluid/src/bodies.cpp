#include "bodies.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "vrflow/message/eigen.hpp"

namespace vrflow::fluid::detail {
namespace {

bool finite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

using Eigen::Vector3d;
using msg::asEigen;

/// x relative to the body's centre, in the body's frame.
msg::Vec3 toLocal(const PreparedBody& body, const Vector3d& x) {
  return msg::toVec3(asEigen(body.orientation).conjugate() * (x - asEigen(body.position)));
}

std::string name(std::uint64_t id) {
  return "body " + std::to_string(id);
}

/// Signed distance of world point x to the body's surface.
double distanceOf(const PreparedBody& body, const Vector3d& x) {
  if (body.surface) return body.surface->distance(msg::toVec3(x));
  return msg::signedDistance(body.shape, toLocal(body, x)).distance;
}

Status finish(PreparedBody& p) {
  if (auto status = msg::validateShape(p.shape); !status) {
    return makeError("fluid: " + name(p.id) + ": bad shape: " + status.error().message);
  }
  if (!std::isfinite(p.mass) || p.mass <= 0.0) {
    return makeError("fluid: " + name(p.id) + ": mass " + std::to_string(p.mass) +
                     " must be finite and positive");
  }
  if (!finite(p.position.data(), 3) || !finite(p.orientation.data(), 4) ||
      !finite(p.linearVelocity.data(), 3) || !finite(p.angularVelocity.data(), 3)) {
    return makeError("fluid: " + name(p.id) + ": position, orientation or velocity is not finite");
  }
  const double qn =
      std::sqrt(p.orientation[0] * p.orientation[0] + p.orientation[1] * p.orientation[1] +
                p.orientation[2] * p.orientation[2] + p.orientation[3] * p.orientation[3]);
  if (qn < 1e-9) return makeError("fluid: " + name(p.id) + ": orientation quaternion is zero");
  for (double& c : p.orientation) c /= qn;
  const double volume = msg::massProperties(p.shape, p.mass).volume;
  if (!std::isfinite(volume) || volume <= 0.0) {
    return makeError("fluid: " + name(p.id) + ": shape has no volume");
  }
  p.density = p.mass / volume;
  p.bounds = msg::worldBounds(p.shape, p.position, p.orientation);
  return {};
}

}  // namespace

Result<PreparedBody> prepareBody(const RigidBody& body, double liquidDensity) {
  PreparedBody p;
  p.id = body.id;
  p.shape = body.shape;
  p.position = body.position;
  p.orientation = body.orientation;
  p.linearVelocity = body.linearVelocity;
  p.angularVelocity = body.angularVelocity;
  p.mass = body.mass;
  p.kinematic = body.kinematic;
  if (body.surface) {
    // A captured user: immovable, as dense as the kinematic bodies, bounded by its voxels.
    p.surface = body.surface;
    p.kinematic = true;
    p.position = body.surface->position;
    p.density = kKinematicDensityRatio * liquidDensity;
    p.bounds = body.surface->bounds;
    return p;
  }
  if (body.kinematic) {
    // Infinite mass, for the projection the shape filled at kKinematicDensityRatio times the
    // liquid's density (finish() derives the density from this mass and the volume).
    const double volume =
        msg::validateShape(body.shape) ? msg::massProperties(body.shape, 1.0).volume : 0.0;
    p.mass = (volume > 0.0 && std::isfinite(volume))
                 ? kKinematicDensityRatio * liquidDensity * volume
                 : 1.0;  // a bad shape: finish() reports it
  }
  if (auto status = finish(p); !status) return status.error();
  return p;
}

Result<PreparedBody> preparePoint(const PointMass& point) {
  if (!std::isfinite(point.radius) || point.radius <= 0.0) {
    return makeError("fluid: node " + std::to_string(point.index) + " of " + name(point.id) +
                     ": radius must be positive");
  }
  PreparedBody p;
  p.id = point.id;
  p.index = point.index;
  p.point = true;
  p.shape = msg::Shape::sphere(point.radius);
  p.position = point.position;
  p.linearVelocity = point.velocity;
  p.mass = point.mass;
  if (auto status = finish(p); !status) return status.error();
  return p;
}

void pushOut(const PreparedBody& body, double* x, double margin) {
  if (body.surface) {
    const msg::Vec3 at{x[0], x[1], x[2]};
    const double distance = body.surface->distance(at);
    if (distance >= 0.0) return;
    const msg::Vec3 n = body.surface->normal(at);
    msg::asVector3(x) += (-distance + margin) * asEigen(n);
    return;
  }
  const auto sd = msg::signedDistance(body.shape, toLocal(body, msg::asVector3(x)));
  if (sd.distance >= 0.0) return;
  const Vector3d n = asEigen(body.orientation) * asEigen(sd.normal);
  const double move = -sd.distance + margin;
  msg::asVector3(x) += move * n;
}

msg::Vec3 rigidVelocity(const PreparedBody& body, const msg::Vec3& x) {
  if (body.surface) return body.surface->velocityAt(x);
  const Vector3d r = asEigen(x) - asEigen(body.position);
  return msg::toVec3(asEigen(body.linearVelocity) + asEigen(body.angularVelocity).cross(r));
}

void rasterise(const Grid& g, const std::vector<PreparedBody>& bodies, std::vector<int>& cellBody,
               std::vector<int>* faceBody) {
  std::fill(cellBody.begin(), cellBody.end(), -1);
  for (int a = 0; a < 3; ++a) std::fill(faceBody[a].begin(), faceBody[a].end(), -1);
  const double o[3] = {g.ox, g.oy, g.oz};
  const int n[3] = {g.nx, g.ny, g.nz};
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const auto& body = bodies[b];
    // Index ranges whose centres may lie in the bounds, for cells (a = -1) and each face kind.
    for (int a = -1; a < 3; ++a) {
      int lo[3], hi[3];
      bool empty = false;
      for (int d = 0; d < 3; ++d) {
        const double shift = (d == a) ? 0.0 : 0.5;
        const int count = n[d] + (d == a ? 1 : 0);
        lo[d] = std::max(0, static_cast<int>(std::ceil((body.bounds.min[d] - o[d]) / g.h - shift)));
        hi[d] = std::min(count - 1,
                         static_cast<int>(std::floor((body.bounds.max[d] - o[d]) / g.h - shift)));
        if (hi[d] < lo[d]) empty = true;
      }
      if (empty) continue;
      for (int k = lo[2]; k <= hi[2]; ++k) {
        for (int j = lo[1]; j <= hi[1]; ++j) {
          for (int i = lo[0]; i <= hi[0]; ++i) {
            Vector3d x{o[0] + (i + 0.5) * g.h, o[1] + (j + 0.5) * g.h, o[2] + (k + 0.5) * g.h};
            if (a >= 0) x[a] -= 0.5 * g.h;
            auto& slot = a < 0 ? cellBody[g.cell(i, j, k)] : faceBody[a][g.face(a, i, j, k)];
            if (slot >= 0) continue;
            if (distanceOf(body, x) < 0.0) slot = static_cast<int>(b);
          }
        }
      }
    }
  }
}

void bodyForceSums(const Grid& g, const PreparedBody& body, int bodyIndex,
                   const std::vector<int>* faceBody, const std::vector<double>* uNew,
                   const std::vector<double>* uOld, const msg::Vec3& gravity, double dt, int k0,
                   const int kEnd[3], double* sums) {
  const double o[3] = {g.ox, g.oy, g.oz};
  for (int a = 0; a < 3; ++a) {
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::max(0, static_cast<int>(std::floor((body.bounds.min[d] - o[d]) / g.h)) - 1);
      hi[d] = std::min(g.fdim(a, d) - 1,
                       static_cast<int>(std::ceil((body.bounds.max[d] - o[d]) / g.h)) + 1);
    }
    lo[2] = std::max(lo[2], k0);
    hi[2] = std::min(hi[2], kEnd[a] - 1);
    double* out = sums + 5 * a;
    for (int k = lo[2]; k <= hi[2]; ++k) {
      for (int j = lo[1]; j <= hi[1]; ++j) {
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const std::size_t f = g.face(a, i, j, k);
          if (faceBody[a][f] != bodyIndex) continue;
          // Momentum change per unit mass on this face, gravity removed: -grad p / rho.
          const double d = uNew[a][f] - uOld[a][f] - gravity[a] * dt;
          out[0] += d;
          out[1] += 1.0;
          Vector3d x{g.ox + (i + 0.5) * g.h, g.oy + (j + 0.5) * g.h, g.oz + (k + 0.5) * g.h};
          x[a] -= 0.5 * g.h;
          Vector3d e = Vector3d::Zero();
          e[a] = d;
          const Vector3d t = (x - asEigen(body.position)).cross(e);
          msg::asVector3(out + 2) += t;
        }
      }
    }
  }
}

BodyForce finishBodyForce(const PreparedBody& body, const double* sums, double dt) {
  BodyForce out;
  out.id = body.id;
  out.index = body.index;
  out.point = body.position;
  out.duration = dt;
  for (int a = 0; a < 3; ++a) {
    if (sums[5 * a + 1] < 1.0) return out;  // too small for the grid on some axis: no force
  }
  msg::Vec3 torque{};
  for (int a = 0; a < 3; ++a) {
    const double* s = sums + 5 * a;
    const int count = static_cast<int>(s[1]);
    out.cells += count;
    // Each face carries mass / count of the body along this axis.
    out.force[a] = body.mass * (s[0] / count) / dt;
    for (int c = 0; c < 3; ++c) torque[c] += body.mass / count * s[2 + c] / dt;
  }
  if (!body.point) out.torque = torque;
  return out;
}

}  // namespace vrflow::fluid::detail
