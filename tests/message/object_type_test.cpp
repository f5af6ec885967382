#include <gtest/gtest.h>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::msg {
namespace {

TEST(ObjectType, IdIsFnv1aOfTheName) {
  EXPECT_EQ(rigidType().id(), fnv1a32("rigid"));
  EXPECT_EQ(pointType().id(), fnv1a32("point"));
}

TEST(ObjectType, BuiltinParameterIndicesMatchTheirConstants) {
  EXPECT_EQ(rigidType().indexOf("position"), RigidParam::kPosition);
  EXPECT_EQ(rigidType().indexOf("sdf"), RigidParam::kSdf);
  EXPECT_EQ(rigidType().indexOf("friction"), RigidParam::kFriction);
  EXPECT_EQ(rigidType().indexOf("restitution"), RigidParam::kRestitution);
  EXPECT_EQ(rigidType().paramCount(), 11u);
  EXPECT_EQ(rigidType().param(RigidParam::kInertia).kind, ParamKind::Mat3);
  EXPECT_EQ(massSpringType().indexOf("bounds"), MassSpringParam::kBounds);
  EXPECT_EQ(massSpringType().param(MassSpringParam::kPinned).kind, ParamKind::Bytes);
  EXPECT_EQ(fluidType().indexOf("pressureField"), FluidParam::kPressureField);
  EXPECT_EQ(fluidType().indexOf("surface"), FluidParam::kSurface);
  EXPECT_EQ(userType().indexOf("sdf"), UserParam::kSdf);
  EXPECT_EQ(pointType().indexOf("mass"), PointParam::kMass);
  EXPECT_FALSE(pointType().indexOf("colour").has_value());
}

TEST(ObjectType, RejectsDuplicateEmptyOrTooManyParameters) {
  EXPECT_FALSE(ObjectType::create("", {}).ok());
  EXPECT_FALSE(ObjectType::create("t", {{"a", ParamKind::Scalar}, {"a", ParamKind::Vec3}}).ok());
  EXPECT_FALSE(ObjectType::create("t", {{"", ParamKind::Scalar}}).ok());
  std::vector<ParamDecl> many;
  many.reserve(65);
  for (int i = 0; i < 65; ++i) many.push_back({"p" + std::to_string(i), ParamKind::Scalar});
  const auto tooMany = ObjectType::create("t", many);
  ASSERT_FALSE(tooMany.ok());
  EXPECT_NE(tooMany.error().message.find("65 parameters"), std::string::npos);
  many.pop_back();
  EXPECT_TRUE(ObjectType::create("t", many).ok());
}

TEST(ParamKind, FixedKindsHaveExactSizesAndArraysMultiples) {
  EXPECT_TRUE(validSizeFor(ParamKind::Vec3, 24));
  EXPECT_FALSE(validSizeFor(ParamKind::Vec3, 16));
  EXPECT_TRUE(validSizeFor(ParamKind::Aabb, 48));
  EXPECT_TRUE(validSizeFor(ParamKind::FloatArray, 0));
  EXPECT_TRUE(validSizeFor(ParamKind::FloatArray, 12));
  EXPECT_FALSE(validSizeFor(ParamKind::FloatArray, 6));
  EXPECT_FALSE(validSizeFor(ParamKind::DoubleArray, 12));
  EXPECT_TRUE(validSizeFor(ParamKind::Bytes, 7));
}

TEST(ObjectTypeRegistry, KnowsTheBuiltinTypes) {
  ObjectTypeRegistry registry;
  for (const char* name : {"rigid", "massspring", "fluid", "user", "point"}) {
    const ObjectType* type = registry.find(name);
    ASSERT_NE(type, nullptr) << name;
    EXPECT_EQ(registry.find(type->id()), type);
  }
  EXPECT_EQ(registry.find("gizmo"), nullptr);
  EXPECT_EQ(registry.find(fnv1a32("gizmo")), nullptr);
}

TEST(ObjectTypeRegistry, AddsNewTypesAndRefusesConflictingOnes) {
  ObjectTypeRegistry registry;
  auto gizmo = ObjectType::create("gizmo", {{"angle", ParamKind::Scalar}});
  ASSERT_TRUE(gizmo.ok());
  const auto added = registry.add(*gizmo);
  ASSERT_TRUE(added.ok()) << added.error().message;
  EXPECT_EQ(registry.find("gizmo"), *added);
  // The same type again is fine; a different list under the same name is not.
  EXPECT_EQ(*registry.add(*gizmo), *added);
  auto other = ObjectType::create("gizmo", {{"angle", ParamKind::Vec3}});
  ASSERT_TRUE(other.ok());
  const auto conflict = registry.add(*other);
  ASSERT_FALSE(conflict.ok());
  EXPECT_NE(conflict.error().message.find("different parameter list"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::msg
