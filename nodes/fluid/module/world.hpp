#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/camera/user_copy.hpp"
#include "vrflow/fluid/solver.hpp"
#include "vrflow/message/reader.hpp"

// The fluid module's copy of the objects it couples with: rigid bodies (and their shape
// resources), captured users (their distance and velocity fields) and, optionally, mass-spring
// nodes as independent point masses. Only changes
// travel, so each chunk updates the copy; objects of other types are ignored.

namespace vrflow::fluid {

class World {
 public:
  /// `nodeRadius` > 0: mass-spring nodes are rasterised as spheres of that radius.
  explicit World(double nodeRadius) : nodeRadius_(nodeRadius) {}

  /// Applies every chunk of a message. Errors (an undecodable shape) are returned, naming it.
  Status apply(const msg::MessageView& message);

  /// Rigid bodies whose shape has arrived, in id order (deterministic); mass 0 means kinematic.
  /// With `near`, only those whose latest bounds meet it (closed boxes, as a route filter
  /// judges) or whose bounds never came.
  std::vector<RigidBody> rigidBodies(const msg::Aabb* near = nullptr) const;
  /// Mass-spring nodes (empty when nodeRadius is 0), in net id then node order; with `near`,
  /// every node of the nets whose bounds meet it (or never came).
  std::vector<PointMass> pointMasses(const msg::Aabb* near = nullptr) const;
  /// Captured users (type `user`) whose distance field has arrived, as kinematic bodies with
  /// their `surface`, in id order; with `near`, those whose bounds meet it. Valid until the next
  /// apply().
  std::vector<RigidBody> users(const msg::Aabb* near = nullptr) const;
  /// Rigid objects seen without their shape (not coupled yet), for the log.
  std::vector<std::string> uncoupled() const;

 private:
  struct Rigid {
    RigidBody body;
    std::uint64_t shapeId = 0;
    std::optional<msg::Aabb> bounds;
  };
  struct Net {
    std::vector<double> positions, velocities, masses;
    std::optional<msg::Aabb> bounds;
  };
  double nodeRadius_;
  std::map<std::uint64_t, Rigid> rigids_;
  std::map<std::uint64_t, Net> nets_;
  std::map<std::uint64_t, msg::Shape> shapes_;
  camera::UserCopy users_;
};

}  // namespace vrflow::fluid
