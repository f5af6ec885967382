#include "vrflow/message/builtin_types.hpp"

#include <utility>

#include "vrflow/base/assert.hpp"

namespace vrflow::msg {
namespace {

ObjectType makeBuiltin(std::string name, std::vector<ParamDecl> params) {
  auto type = ObjectType::create(std::move(name), std::move(params));
  VRFLOW_ASSERT(type.ok(), "a built-in object type is malformed");
  return std::move(type).value();
}

}  // namespace

const ObjectType& rigidType() {
  static const ObjectType type = makeBuiltin("rigid", {
                                                          {"position", ParamKind::Vec3},
                                                          {"orientation", ParamKind::Quat},
                                                          {"linearVelocity", ParamKind::Vec3},
                                                          {"angularVelocity", ParamKind::Vec3},
                                                          {"mass", ParamKind::Scalar},
                                                          {"inertia", ParamKind::Mat3},
                                                          {"bounds", ParamKind::Aabb},
                                                          {"shape", ParamKind::Id},
                                                          {"sdf", ParamKind::Id},
                                                          {"friction", ParamKind::Scalar},
                                                          {"restitution", ParamKind::Scalar},
                                                      });
  return type;
}

const ObjectType& massSpringType() {
  static const ObjectType type =
      makeBuiltin("massspring", {
                                    {"positions", ParamKind::DoubleArray},
                                    {"velocities", ParamKind::DoubleArray},
                                    {"masses", ParamKind::DoubleArray},
                                    {"pinned", ParamKind::Bytes},
                                    {"springs", ParamKind::Bytes},
                                    {"bounds", ParamKind::Aabb},
                                    {"surface", ParamKind::Bytes},
                                });
  return type;
}

const ObjectType& fluidType() {
  static const ObjectType type = makeBuiltin("fluid", {
                                                          {"bounds", ParamKind::Aabb},
                                                          {"particles", ParamKind::Id},
                                                          {"velocityField", ParamKind::Id},
                                                          {"pressureField", ParamKind::Id},
                                                          {"surface", ParamKind::Id},
                                                      });
  return type;
}

const ObjectType& userType() {
  static const ObjectType type = makeBuiltin("user", {
                                                         {"position", ParamKind::Vec3},
                                                         {"orientation", ParamKind::Quat},
                                                         {"bounds", ParamKind::Aabb},
                                                         {"mesh", ParamKind::Id},
                                                         {"sdf", ParamKind::Id},
                                                         {"velocityField", ParamKind::Id},
                                                     });
  return type;
}

const ObjectType& pointType() {
  static const ObjectType type = makeBuiltin("point", {
                                                          {"position", ParamKind::Vec3},
                                                          {"velocity", ParamKind::Vec3},
                                                          {"mass", ParamKind::Scalar},
                                                      });
  return type;
}

std::array<const ObjectType*, 5> builtinTypes() {
  return {&rigidType(), &massSpringType(), &fluidType(), &userType(), &pointType()};
}

}  // namespace vrflow::msg
