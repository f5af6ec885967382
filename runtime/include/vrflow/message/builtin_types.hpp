#pragma once

#include <array>
#include <cstdint>

#include "vrflow/message/object_type.hpp"

// The object types every vrflow process knows, with their parameter indices as constants so
// that node code writes `obj.vec3(RigidParam::kPosition)` and never looks names up.

namespace vrflow::msg {

/// Rigid body (nodes/rigid).
const ObjectType& rigidType();
/// Parameter indices of rigidType().
struct RigidParam {
  enum : std::uint32_t {
    kPosition,         ///< Vec3
    kOrientation,      ///< Quat
    kLinearVelocity,   ///< Vec3
    kAngularVelocity,  ///< Vec3
    kMass,             ///< Scalar
    kInertia,          ///< Mat3
    kBounds,           ///< Aabb
    kShape,            ///< Id of a mesh resource
    kSdf,              ///< Id of a signed-distance-field resource
    kFriction,         ///< Scalar, the surface's friction coefficient (absent: the interactor's)
    kRestitution       ///< Scalar, the surface's restitution (absent: the interactor's)
  };
};

/// Mass-spring net (nodes/massspring).
const ObjectType& massSpringType();
/// Parameter indices of massSpringType().
struct MassSpringParam {
  enum : std::uint32_t {
    kPositions,   ///< DoubleArray, xyz per mass
    kVelocities,  ///< DoubleArray, xyz per mass
    kMasses,      ///< DoubleArray
    kPinned,      ///< Bytes, one per mass (0 free, 1 pinned)
    kSprings,     ///< Bytes, node-defined spring records
    kBounds,      ///< Aabb
    kSurface      ///< Bytes, u32 mass indices, three per triangle: the net's surface for drawing
  };
};

/// Fluid (nodes/fluid).
const ObjectType& fluidType();
/// Parameter indices of fluidType().
struct FluidParam {
  enum : std::uint32_t {
    kBounds,         ///< Aabb
    kParticles,      ///< Id of a resource
    kVelocityField,  ///< Id of a vector-field resource
    kPressureField,  ///< Id of a scalar-field resource
    kSurface         ///< Id of a Mesh resource: the liquid's surface (triangles)
  };
};

/// A captured user (nodes/camera).
const ObjectType& userType();
/// Parameter indices of userType().
struct UserParam {
  enum : std::uint32_t {
    kPosition,      ///< Vec3
    kOrientation,   ///< Quat
    kBounds,        ///< Aabb
    kMesh,          ///< Id of a mesh resource
    kSdf,           ///< Id of a signed-distance-field resource
    kVelocityField  ///< Id of a vector-field resource: the velocity of the surface (m/s)
  };
};

/// A point mass (the runtime's own demo).
const ObjectType& pointType();
/// Parameter indices of pointType().
struct PointParam {
  enum : std::uint32_t {
    kPosition,  ///< Vec3
    kVelocity,  ///< Vec3
    kMass       ///< Scalar
  };
};

/// Every built-in type, in the order above.
std::array<const ObjectType*, 5> builtinTypes();

}  // namespace vrflow::msg
