#include "vrflow/message/shape.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

namespace vrflow::msg {
namespace {

// A closed triangle mesh drawn from a render mesh, to check winding and volume.
Shape meshFrom(const RenderMesh& render) {
  std::vector<double> vertices(render.xyz.begin(), render.xyz.end());
  return Shape::triangleMesh(std::move(vertices), render.indices);
}

// The unit cube [-0.5, 0.5]^3 as 8 vertices and 12 outward triangles.
Shape cubeHull() {
  std::vector<double> v;
  for (int i = 0; i < 8; ++i) {
    v.push_back((i & 1) ? 0.5 : -0.5);
    v.push_back((i & 2) ? 0.5 : -0.5);
    v.push_back((i & 4) ? 0.5 : -0.5);
  }
  std::vector<std::uint32_t> t = {0, 2, 3, 0, 3, 1,   // z = -0.5
                                  4, 5, 7, 4, 7, 6,   // z = +0.5
                                  0, 1, 5, 0, 5, 4,   // y = -0.5
                                  2, 6, 7, 2, 7, 3,   // y = +0.5
                                  0, 4, 6, 0, 6, 2,   // x = -0.5
                                  1, 3, 7, 1, 7, 5};  // x = +0.5
  return Shape::convexHull(std::move(v), std::move(t));
}

TEST(Shape, EveryKindRoundTripsThroughItsBytes) {
  const Shape shapes[] = {Shape::sphere(0.5), Shape::box({0.1, 0.2, 0.3}), Shape::capsule(0.2, 0.4),
                          cubeHull(), meshFrom(renderMesh(Shape::sphere(1.0), 8))};
  for (const Shape& shape : shapes) {
    ASSERT_TRUE(validateShape(shape).ok());
    const auto bytes = encodeShape(shape);
    EXPECT_EQ(bytes.size() % 8, 0u);
    auto decoded = decodeShape(bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.error().message;
    EXPECT_EQ(decoded.value(), shape);
  }
}

TEST(Shape, DecodeRejectsForgedBytes) {
  auto bytes = encodeShape(cubeHull());
  EXPECT_FALSE(decodeShape(std::span(bytes).first(40)).ok());                 // truncated header
  EXPECT_FALSE(decodeShape(std::span(bytes).first(bytes.size() - 48)).ok());  // truncated body
  auto badMagic = bytes;
  badMagic[0] = std::byte{'X'};
  EXPECT_FALSE(decodeShape(badMagic).ok());
  auto badKind = bytes;
  const std::uint32_t nine = 9;
  std::memcpy(badKind.data() + 4, &nine, 4);
  EXPECT_FALSE(decodeShape(badKind).ok());
  auto huge = bytes;
  const std::uint32_t many = 0xFFFFFFFFu;
  std::memcpy(huge.data() + 48, &many, 4);
  EXPECT_FALSE(decodeShape(huge).ok());
  auto badIndex = bytes;
  const std::uint32_t outOfRange = 8;
  std::memcpy(badIndex.data() + 56 + 24 * 8, &outOfRange, 4);
  const auto rejected = decodeShape(badIndex);
  ASSERT_FALSE(rejected.ok());
  EXPECT_NE(rejected.error().message.find("out of range"), std::string::npos);
  auto nan = encodeShape(Shape::sphere(1.0));
  const double notANumber = std::nan("");
  std::memcpy(nan.data() + 8, &notANumber, 8);
  EXPECT_FALSE(decodeShape(nan).ok());
}

TEST(Shape, ValidationNamesTheProblem) {
  EXPECT_FALSE(validateShape(Shape::sphere(0.0)).ok());
  EXPECT_FALSE(validateShape(Shape::box({1.0, -1.0, 1.0})).ok());
  EXPECT_FALSE(validateShape(Shape::capsule(0.1, -0.5)).ok());
  EXPECT_FALSE(validateShape(Shape::convexHull({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2})).ok());
  EXPECT_FALSE(validateShape(Shape::triangleMesh({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1})).ok());
}

TEST(Shape, PrimitiveMassPropertiesAreTheTextbookOnes) {
  const auto sphere = massProperties(Shape::sphere(2.0), 3.0);
  EXPECT_NEAR(sphere.volume, 4.0 / 3.0 * std::numbers::pi * 8.0, 1e-12);
  EXPECT_NEAR(sphere.inertia[0], 0.4 * 3.0 * 4.0, 1e-12);
  const auto box = massProperties(Shape::box({0.5, 1.0, 1.5}), 12.0);
  EXPECT_NEAR(box.volume, 6.0, 1e-12);
  EXPECT_NEAR(box.inertia[0], 12.0 / 12.0 * (4.0 + 9.0), 1e-12);
  EXPECT_NEAR(box.inertia[4], 12.0 / 12.0 * (1.0 + 9.0), 1e-12);
  EXPECT_NEAR(box.inertia[8], 12.0 / 12.0 * (1.0 + 4.0), 1e-12);
  EXPECT_EQ(box.inertia[1], 0.0);
  // A capsule with no cylinder is a sphere.
  const auto ball = massProperties(Shape::capsule(2.0, 0.0), 3.0);
  EXPECT_NEAR(ball.volume, sphere.volume, 1e-12);
  EXPECT_NEAR(ball.inertia[0], sphere.inertia[0], 1e-12);
  EXPECT_NEAR(ball.inertia[4], sphere.inertia[4], 1e-12);
}

TEST(Shape, MeshMassPropertiesMatchTheEquivalentPrimitive) {
  const auto hull = massProperties(cubeHull(), 6.0);
  const auto box = massProperties(Shape::box({0.5, 0.5, 0.5}), 6.0);
  EXPECT_NEAR(hull.volume, 1.0, 1e-12);
  for (std::size_t i = 0; i < 9; ++i) EXPECT_NEAR(hull.inertia[i], box.inertia[i], 1e-12) << i;
  // Render meshes are closed and wound outward: their volume is positive and close to the shape's.
  const auto sphereMesh = massProperties(meshFrom(renderMesh(Shape::sphere(1.0), 32)), 1.0);
  EXPECT_NEAR(sphereMesh.volume, 4.0 / 3.0 * std::numbers::pi, 0.05 * 4.0);
  const auto capsuleShape = Shape::capsule(0.3, 0.5);
  const auto capsuleMesh = massProperties(meshFrom(renderMesh(capsuleShape, 32)), 1.0);
  EXPECT_NEAR(capsuleMesh.volume, massProperties(capsuleShape, 1.0).volume,
              0.03 * massProperties(capsuleShape, 1.0).volume);
  const auto boxMesh = massProperties(meshFrom(renderMesh(Shape::box({0.5, 1.0, 1.5}))), 12.0);
  EXPECT_NEAR(boxMesh.volume, 6.0, 1e-6);
  EXPECT_NEAR(boxMesh.inertia[0], 13.0, 1e-5);
}

TEST(Shape, SignedDistanceOfPrimitives) {
  const auto s = signedDistance(Shape::sphere(1.0), {0.0, 3.0, 0.0});
  EXPECT_DOUBLE_EQ(s.distance, 2.0);
  EXPECT_EQ(s.normal, (Vec3{0.0, 1.0, 0.0}));
  const Shape box = Shape::box({1.0, 2.0, 3.0});
  EXPECT_DOUBLE_EQ(signedDistance(box, {0.0, 0.0, 2.5}).distance, -0.5);
  EXPECT_EQ(signedDistance(box, {0.0, 0.0, 2.5}).normal, (Vec3{0.0, 0.0, 1.0}));
  EXPECT_DOUBLE_EQ(signedDistance(box, {4.0, 6.0, 0.0}).distance, 5.0);
  const Shape capsule = Shape::capsule(0.5, 1.0);
  EXPECT_DOUBLE_EQ(signedDistance(capsule, {0.0, 2.0, 0.0}).distance, 0.5);
  EXPECT_DOUBLE_EQ(signedDistance(capsule, {2.0, 0.3, 0.0}).distance, 1.5);
  EXPECT_DOUBLE_EQ(signedDistance(capsule, {0.25, 0.0, 0.0}).distance, -0.25);
}

TEST(Shape, SignedDistanceOfHullsAndMeshes) {
  const Shape hull = cubeHull();
  EXPECT_NEAR(signedDistance(hull, {0.0, 0.0, 0.0}).distance, -0.5, 1e-12);
  EXPECT_NEAR(signedDistance(hull, {0.0, 0.9, 0.0}).distance, 0.4, 1e-12);
  EXPECT_NEAR(signedDistance(hull, {0.0, 0.9, 0.0}).normal[1], 1.0, 1e-12);
  const Shape mesh = Shape::triangleMesh(hull.vertices, hull.indices);
  EXPECT_NEAR(signedDistance(mesh, {0.1, 0.2, 0.0}).distance, -0.3, 1e-12);
  EXPECT_NEAR(signedDistance(mesh, {1.5, 1.5, 0.0}).distance, std::sqrt(2.0), 1e-12);
}

TEST(Shape, WorldBoundsFollowTheRotation) {
  // A quarter turn about z maps the box's x extent onto y.
  const double s = std::sqrt(0.5);
  const Quat quarter{0.0, 0.0, s, s};
  const Aabb box = worldBounds(Shape::box({1.0, 2.0, 3.0}), {10.0, 0.0, 0.0}, quarter);
  EXPECT_NEAR(box.min[0], 8.0, 1e-12);
  EXPECT_NEAR(box.max[1], 1.0, 1e-12);
  EXPECT_NEAR(box.max[2], 3.0, 1e-12);
  const Vec3 x = rotate(quarter, {1.0, 0.0, 0.0});
  EXPECT_NEAR(x[1], 1.0, 1e-12);
  const Vec3 back = rotateInverse(quarter, x);
  EXPECT_NEAR(back[0], 1.0, 1e-12);
  const Aabb capsule = worldBounds(Shape::capsule(0.5, 1.0), {0.0, 0.0, 0.0}, quarter);
  EXPECT_NEAR(capsule.max[0], 1.5, 1e-12);
  EXPECT_NEAR(capsule.max[1], 0.5, 1e-12);
  EXPECT_EQ(localBounds(cubeHull()).max, (Vec3{0.5, 0.5, 0.5}));
}

}  // namespace
}  // namespace vrflow::msg
