// The viewer's side of the surface: the scene cache keeps a surface mesh's triangles, and the
// renderer draws a fluid object that names one as water instead of points.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "../viewer/scene_messages.hpp"
#include "vrflow/viewer/renderer.hpp"

namespace vrflow::viewer {
namespace {

using testing::feed;

// A 2 x 1 m quad at z = 0, centred on (0, 1, 0), its triangles facing +z (the camera).
const std::vector<float> kQuad{-1, 0.5f, 0, 1, 0.5f, 0, 1, 1.5f, 0, -1, 1.5f, 0};
const std::vector<std::uint32_t> kTriangles{0, 1, 2, 0, 2, 3};

// Fluid object 50 naming the quad (resource 500) by `param`: its surface or its particles.
bool feedQuad(SceneCache& scene, std::uint32_t param) {
  return feed(scene, [&](msg::MessageBuilder& b) {
    b.addMesh(500, true, kQuad, kTriangles);
    b.addObject(50, msg::fluidType(), msg::ObjectOp::Add).set(param, std::uint64_t{500});
  });
}

Image renderCentre(const SceneCache& scene) {
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.ground = false;
  auto renderer = Renderer::create(s);
  EXPECT_TRUE(renderer.ok());
  Camera camera;
  camera.eye = {0.0, 1.0, 5.0};
  camera.target = {0.0, 1.0, 0.0};
  auto image = renderer->render(scene, camera);
  EXPECT_TRUE(image.ok());
  return *image;
}

std::array<int, 3> centre(const Image& image) {
  const std::size_t at = 3 * (static_cast<std::size_t>(image.height / 2) * image.width +
                              static_cast<std::size_t>(image.width / 2));
  return {image.rgb[at], image.rgb[at + 1], image.rgb[at + 2]};
}

TEST(SurfaceDrawing, FluidObjectNamingASurfaceIsDrawnAsBlueWater) {
  SceneCache scene;
  ASSERT_TRUE(feedQuad(scene, msg::FluidParam::kSurface));
  ASSERT_NE(scene.meshIndices(500), nullptr);
  EXPECT_EQ(*scene.meshIndices(500), kTriangles);
  const auto water = centre(renderCentre(scene));
  const auto background = RenderSettings{}.background;
  // Lit water over the background: blue above green above red, and not the background.
  EXPECT_GT(water[2], water[1]);
  EXPECT_GT(water[1], water[0]);
  EXPECT_GT(water[2] - water[0], 60);
  EXPECT_NE(water[0], static_cast<int>(background[0] * 255.0f + 0.5f));
}

TEST(SurfaceDrawing, WithoutTheSurfaceTheSameMeshIsDrawnAsParticlesOnly) {
  // The same mesh named as particles: only its four vertices are drawn, the centre stays empty.
  SceneCache scene;
  ASSERT_TRUE(feedQuad(scene, msg::FluidParam::kParticles));
  SceneCache empty;
  EXPECT_EQ(centre(renderCentre(scene)), centre(renderCentre(empty)));
}

// A captured user's hull (a user object naming a mesh) is drawn opaque, in its skin colour.
TEST(SurfaceDrawing, AUserObjectIsDrawnAsItsMeshInSkinColour) {
  SceneCache scene;
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    b.addMesh(600, true, kQuad, kTriangles);
    b.addObject(60, msg::userType(), msg::ObjectOp::Add)
        .set(msg::UserParam::kMesh, std::uint64_t{600})
        .set(msg::UserParam::kPosition, msg::Vec3{0, 1, 0});
  }));
  const auto user = centre(renderCentre(scene));
  // Lit skin: red above green above blue, clearly not the background.
  EXPECT_GT(user[0], user[1]);
  EXPECT_GT(user[1], user[2]);
  EXPECT_GT(user[0] - user[2], 40);
  SceneCache empty;
  EXPECT_NE(user, centre(renderCentre(empty)));
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) { b.addDelete(60, msg::userType()); }));
  EXPECT_EQ(scene.meshIndices(600), nullptr);
}

// A surface resource no object names any more is dropped with its triangles (the cache does not
// grow when a sender replaces its objects).
TEST(SurfaceDrawing, TheSurfaceIsDroppedWithItsObject) {
  SceneCache scene;
  ASSERT_TRUE(feedQuad(scene, msg::FluidParam::kSurface));
  ASSERT_NE(scene.meshIndices(500), nullptr);
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) { b.addDelete(50, msg::fluidType()); }));
  EXPECT_EQ(scene.meshIndices(500), nullptr);
  EXPECT_EQ(scene.particles(500), nullptr);
}

}  // namespace
}  // namespace vrflow::viewer
