// The scene cache follows adds, partial updates and deletes, and survives forged resources.
#include "vrflow/viewer/scene_cache.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "scene_messages.hpp"
#include "vrflow/viewer/renderer.hpp"

namespace vrflow::viewer {
namespace {

using testing::addNet;
using testing::addRigid;
using testing::addShape;
using testing::feed;

struct LoggedScene {
  std::vector<std::string> lines;
  SceneCache scene{16, [this](const std::string& line) { lines.push_back(line); }};
  bool logged(const std::string& text) const {
    for (const auto& line : lines) {
      if (line.find(text) != std::string::npos) return true;
    }
    return false;
  }
};

TEST(SceneCache, AddCarriesEveryParameter) {
  LoggedScene s;
  const msg::Quat q{0.0, 0.6, 0.0, 0.8};
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::box({1, 2, 3}));
    addRigid(b, 1, {1, 2, 3}, 100, q);
  }));
  const CachedObject* o = s.scene.find(1);
  ASSERT_NE(o, nullptr);
  EXPECT_EQ(o->kind, ObjectKind::Rigid);
  EXPECT_EQ(o->position, (msg::Vec3{1, 2, 3}));
  EXPECT_EQ(o->orientation, q);
  EXPECT_EQ(o->shapeId, 100u);
  ASSERT_NE(s.scene.shapeMesh(100), nullptr);
  EXPECT_EQ(s.scene.shapeMesh(100)->indices.size(), 36u);  // 12 triangles
  EXPECT_TRUE(s.lines.empty());
}

TEST(SceneCache, UpdateChangesOnlyTheParametersItCarries) {
  LoggedScene s;
  const msg::Quat q{0.0, 0.6, 0.0, 0.8};
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::sphere(1));
    addRigid(b, 1, {1, 2, 3}, 100, q);
    addRigid(b, 2, {5, 5, 5}, 100);
  }));
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addObject(1, msg::rigidType(), msg::ObjectOp::Update)
        .set(msg::RigidParam::kPosition, msg::Vec3{4, 5, 6});
  }));
  const CachedObject* o = s.scene.find(1);
  ASSERT_NE(o, nullptr);
  EXPECT_EQ(o->position, (msg::Vec3{4, 5, 6}));
  EXPECT_EQ(o->orientation, q);                                // kept
  EXPECT_EQ(o->shapeId, 100u);                                 // kept
  EXPECT_EQ(s.scene.find(2)->position, (msg::Vec3{5, 5, 5}));  // untouched
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addObject(1, msg::rigidType(), msg::ObjectOp::Update)
        .set(msg::RigidParam::kOrientation, msg::Quat{0, 0, 0, 1});
  }));
  EXPECT_EQ(s.scene.find(1)->position, (msg::Vec3{4, 5, 6}));
  EXPECT_EQ(s.scene.find(1)->orientation, (msg::Quat{0, 0, 0, 1}));
}

TEST(SceneCache, NetPositionsUpdateAndItsSurfaceStays) {
  LoggedScene s;
  const std::vector<double> xyz{0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<std::uint32_t> surface{0, 1, 2};
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) { addNet(b, 9, xyz, surface); }));
  const std::vector<double> moved{0, 0, 1, 1, 0, 1, 0, 1, 1};
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addObject(9, msg::massSpringType(), msg::ObjectOp::Update)
        .set(msg::MassSpringParam::kPositions, std::span<const double>(moved));
  }));
  const CachedObject* net = s.scene.find(9);
  ASSERT_NE(net, nullptr);
  EXPECT_EQ(net->kind, ObjectKind::MassSpring);
  EXPECT_EQ(net->positions, moved);
  EXPECT_EQ(net->surface, surface);
}

TEST(SceneCache, DeleteRemovesTheObject) {
  LoggedScene s;
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::sphere(1));
    addRigid(b, 1, {0, 0, 0}, 100);
    addRigid(b, 2, {0, 0, 0}, 100);
  }));
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) { b.addDelete(1, msg::rigidType()); }));
  EXPECT_EQ(s.scene.find(1), nullptr);
  EXPECT_NE(s.scene.find(2), nullptr);
  EXPECT_EQ(s.scene.objects().size(), 1u);
  EXPECT_NE(s.scene.shapeMesh(100), nullptr);  // the resource outlives its users
}

TEST(SceneCache, AddOfAnExistingIdReplacesTheWholeObject) {
  LoggedScene s;
  const std::vector<double> xyz{0, 0, 0, 1, 0, 0, 0, 1, 0};
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) { addNet(b, 9, xyz, {0, 1, 2}); }));
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addObject(9, msg::massSpringType(), msg::ObjectOp::Add)
        .set(msg::MassSpringParam::kPositions, std::span<const double>(xyz));
  }));
  EXPECT_TRUE(s.scene.find(9)->surface.empty());  // the new add has no surface
}

TEST(SceneCache, StaticShapeIsDecodedOnce) {
  LoggedScene s;
  ASSERT_TRUE(
      feed(s.scene, [&](msg::MessageBuilder& b) { addShape(b, 100, msg::Shape::sphere(1)); }));
  const DrawMesh* first = s.scene.shapeMesh(100);
  ASSERT_NE(first, nullptr);
  // The same id again (another sender's copy) keeps the mesh already built.
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::box({1, 1, 1}));
  }));
  EXPECT_EQ(s.scene.shapeMesh(100), first);
}

TEST(SceneCache, ForgedShapeIsRejectedWithALogAndNotDrawn) {
  LoggedScene s;
  auto bytes = msg::encodeShape(msg::Shape::convexHull({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1},
                                                       {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}));
  // An index far out of range: the kind of lie a forged resource tells.
  const std::uint32_t bad = 1000;
  std::memcpy(bytes.data() + 56 + 24 * 4, &bad, 4);
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addRawResource(100, false, bytes);
    addRigid(b, 1, {0, 1, 0}, 100);
  }));
  EXPECT_EQ(s.scene.shapeMesh(100), nullptr);
  EXPECT_EQ(s.scene.stats().rejectedShapes, 1u);
  EXPECT_TRUE(s.logged("shape resource 100 rejected")) << (s.lines.empty() ? "" : s.lines[0]);
  // The scene still renders: the object is simply not there.
  RenderSettings settings;
  settings.width = 64;
  settings.height = 48;
  settings.ground = false;
  auto renderer = Renderer::create(settings);
  ASSERT_TRUE(renderer.ok());
  Camera camera;
  camera.eye = {0, 1, 5};
  camera.target = {0, 1, 0};
  const auto image = renderer->render(s.scene, camera);
  ASSERT_TRUE(image.ok());
  const auto centre = image->at(32, 24);
  EXPECT_EQ(centre[0], static_cast<std::uint8_t>(std::lround(settings.background[0] * 255)));
}

TEST(SceneCache, TruncatedShapeIsRejected) {
  LoggedScene s;
  auto bytes = msg::encodeShape(msg::Shape::box({1, 1, 1}));
  bytes.resize(20);
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) { b.addRawResource(100, false, bytes); }));
  EXPECT_EQ(s.scene.shapeMesh(100), nullptr);
  EXPECT_TRUE(s.logged("shape resource 100 rejected"));
}

TEST(SceneCache, ResourceWithoutShapeMagicNamedAsAShapeIsRejected) {
  LoggedScene s;
  const std::vector<std::byte> junk(48, std::byte{0x5a});
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addRawResource(100, false, junk);
    addRigid(b, 1, {0, 1, 0}, 100);
  }));
  EXPECT_EQ(s.scene.shapeMesh(100), nullptr);
  EXPECT_TRUE(s.logged("no shape magic"));
  EXPECT_EQ(s.scene.stats().rejectedShapes, 1u);
}

TEST(SceneCache, ShapeArrivingAfterItsObjectIsUsed) {
  LoggedScene s;
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) { addRigid(b, 1, {0, 1, 0}, 100); }));
  EXPECT_EQ(s.scene.shapeMesh(100), nullptr);
  ASSERT_TRUE(
      feed(s.scene, [&](msg::MessageBuilder& b) { addShape(b, 100, msg::Shape::sphere(1)); }));
  EXPECT_NE(s.scene.shapeMesh(100), nullptr);
  EXPECT_TRUE(s.lines.empty());
}

TEST(SceneCache, UpdateOfAnUnknownObjectIsLoggedAndKept) {
  LoggedScene s;
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addObject(3, msg::rigidType(), msg::ObjectOp::Update)
        .set(msg::RigidParam::kPosition, msg::Vec3{1, 1, 1});
  }));
  ASSERT_NE(s.scene.find(3), nullptr);
  EXPECT_EQ(s.scene.find(3)->position, (msg::Vec3{1, 1, 1}));
  EXPECT_TRUE(s.logged("update for unknown object 3"));
}

TEST(SceneCache, FluidParticlesFromARawFloatArray) {
  LoggedScene s;
  const std::vector<float> xyz{1, 2, 3, 4, 5, 6};
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addRawResource(500, true, std::as_bytes(std::span(xyz)));
    b.addObject(50, msg::fluidType(), msg::ObjectOp::Add)
        .set(msg::FluidParam::kParticles, std::uint64_t{500});
  }));
  ASSERT_NE(s.scene.particles(500), nullptr);
  EXPECT_EQ(*s.scene.particles(500), xyz);
  EXPECT_EQ(s.scene.find(50)->particlesId, 500u);
}

TEST(SceneCache, ResourcesNoObjectNamesAreNotKept) {
  LoggedScene s;
  const std::vector<float> xyz{1, 2, 3};
  for (std::uint64_t id = 1000; id < 1100; ++id) {
    ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
      b.addRawResource(id, true, std::as_bytes(std::span(xyz)));
      b.addMesh(id + 5000, true, xyz, {});
    }));
  }
  EXPECT_EQ(s.scene.heldResources(), 0u);
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addMesh(7, true, xyz, {});
    b.addObject(50, msg::fluidType(), msg::ObjectOp::Add)
        .set(msg::FluidParam::kParticles, std::uint64_t{7});
  }));
  EXPECT_EQ(s.scene.heldResources(), 1u);
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) { b.addDelete(50, msg::fluidType()); }));
  EXPECT_EQ(s.scene.heldResources(), 0u);
}

TEST(SceneCache, EventsAndUnknownTypesAreIgnored) {
  LoggedScene s;
  // A type of some package the viewer knows nothing of (users are drawn since they have a mesh).
  const auto created = msg::ObjectType::create("custom", {{"position", msg::ParamKind::Vec3}});
  ASSERT_TRUE(created.ok());
  const msg::ObjectType& custom = created.value();
  ASSERT_TRUE(feed(s.scene, [&](msg::MessageBuilder& b) {
    b.addForce(1, msg::ForceEvent{});
    b.addObject(2, custom, msg::ObjectOp::Add).set(0, msg::Vec3{});
  }));
  EXPECT_TRUE(s.scene.objects().empty());
  EXPECT_EQ(s.scene.stats().ignoredChunks, 2u);
}

TEST(DrawMesh, BoxHasFlatFacesAndSphereSmoothNormals) {
  const auto box = msg::renderMesh(msg::Shape::box({1, 1, 1}));
  const DrawMesh flat = buildDrawMesh(box.xyz, box.indices);
  EXPECT_EQ(flat.xyz.size(), 24u * 3u);  // four corners per face, none shared across faces
  for (std::size_t i = 0; i < flat.normals.size(); i += 3) {
    const float big = std::max(
        {std::abs(flat.normals[i]), std::abs(flat.normals[i + 1]), std::abs(flat.normals[i + 2])});
    EXPECT_NEAR(big, 1.0f, 1e-6f);  // an axis direction
  }
  const auto sphere = msg::renderMesh(msg::Shape::sphere(2.0), 16);
  const DrawMesh smooth = buildDrawMesh(sphere.xyz, sphere.indices);
  for (std::size_t i = 0; i < smooth.xyz.size(); i += 3) {
    // On a sphere about the origin the normal points along the position.
    const float r =
        std::sqrt(smooth.xyz[i] * smooth.xyz[i] + smooth.xyz[i + 1] * smooth.xyz[i + 1] +
                  smooth.xyz[i + 2] * smooth.xyz[i + 2]);
    const float cosine =
        (smooth.xyz[i] * smooth.normals[i] + smooth.xyz[i + 1] * smooth.normals[i + 1] +
         smooth.xyz[i + 2] * smooth.normals[i + 2]) /
        r;
    EXPECT_GT(cosine, 0.97f);
  }
}

}  // namespace
}  // namespace vrflow::viewer
