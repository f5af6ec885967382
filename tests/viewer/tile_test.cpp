// Tiles of a display wall: off-axis sub-frusta that stitch into the whole view, and the volume
// of interest each tile publishes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene_messages.hpp"
#include "vrflow/viewer/renderer.hpp"
#include "vrflow/viewer/view_volume.hpp"
#include "wall_scene.hpp"

namespace vrflow::viewer {
namespace {

using testing::addNet;
using testing::addRigid;
using testing::addShape;
using testing::feed;
using testing::onAnEdge;
using testing::wallCamera;
using testing::wallScene;

Image renderWith(const SceneCache& scene, RenderSettings settings) {
  auto renderer = Renderer::create(settings);
  EXPECT_TRUE(renderer.ok()) << renderer.error().message;
  auto image = renderer->render(scene, wallCamera());
  EXPECT_TRUE(image.ok()) << image.error().message;
  return *image;
}

TEST(Tile, ParsesColumnRowAndWallSizeAndRefusesTilesOutsideTheWall) {
  const auto tile = parseTile("1 0 2 3");
  ASSERT_TRUE(tile.ok());
  EXPECT_EQ(*tile, (Tile{1, 0, 2, 3}));
  EXPECT_EQ(*parseTile("0 0 1 1"), Tile{});
  for (const char* bad : {"", "0 0 1", "0 0 1 1 1", "2 0 2 2", "0 2 2 2", "-1 0 2 2", "0 0 0 1",
                          "a b c d", "0.5 0 2 2"}) {
    EXPECT_FALSE(parseTile(bad).ok()) << bad;
  }
  EXPECT_NE(parseTile("2 0 2 2").error().message.find("0 <= COL < COLS"), std::string::npos);
}

TEST(Tile, FrustaOfAWallSplitTheWholeWindowExactly) {
  Camera camera;
  const Frustum whole = tileFrustum(camera, Tile{}, 640, 360);
  EXPECT_DOUBLE_EQ(whole.right, -whole.left);
  EXPECT_DOUBLE_EQ(whole.top, -whole.bottom);
  EXPECT_NEAR(whole.right / whole.top, 640.0 / 360.0, 1e-12);
  // Tiles of 320 x 180 in a 2 x 2 wall: the same whole window, cut in four.
  const Frustum topLeft = tileFrustum(camera, Tile{0, 0, 2, 2}, 320, 180);
  const Frustum bottomRight = tileFrustum(camera, Tile{1, 1, 2, 2}, 320, 180);
  EXPECT_DOUBLE_EQ(topLeft.left, whole.left);
  EXPECT_NEAR(topLeft.right, 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(topLeft.top, whole.top);
  EXPECT_NEAR(topLeft.bottom, 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(bottomRight.right, whole.right);
  EXPECT_DOUBLE_EQ(bottomRight.bottom, whole.bottom);
}

// Whether the pixel at (x, y) lies on an edge of `image`: a neighbour has another colour.
// The 4 tiles of a 2 x 2 wall (W x H each), stitched, against one viewer of 2W x 2H: the same
// camera, supersample 1, ground, shadows and net lines on. The tiles' projections differ from
// the whole view's in the last bits, so a pixel whose centre lies on a primitive's edge may be
// rounded the other way: a few edge pixels may differ, nothing else.
TEST(Tile, FourTilesOfATwoByTwoWallStitchIntoTheWholeView) {
  const SceneCache scene = wallScene();
  const int w = 160, h = 100;
  RenderSettings whole;
  whole.width = 2 * w;
  whole.height = 2 * h;
  whole.supersample = 1;
  const Image reference = renderWith(scene, whole);
  Image stitched = reference;
  std::fill(stitched.rgb.begin(), stitched.rgb.end(), std::uint8_t{0});
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 2; ++col) {
      RenderSettings part = whole;
      part.width = w;
      part.height = h;
      part.tile = Tile{col, row, 2, 2};
      const Image tile = renderWith(scene, part);
      ASSERT_EQ(tile.width, w);
      ASSERT_EQ(tile.height, h);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          for (std::size_t c = 0; c < 3; ++c) {
            stitched.rgb[(static_cast<std::size_t>(row * h + y) * 2 * w + col * w + x) * 3 + c] =
                tile.rgb[(static_cast<std::size_t>(y) * w + x) * 3 + c];
          }
        }
      }
    }
  }
  int differing = 0, inside = 0;
  for (int y = 0; y < 2 * h; ++y) {
    for (int x = 0; x < 2 * w; ++x) {
      if (stitched.at(x, y) == reference.at(x, y)) continue;
      ++differing;
      if (!onAnEdge(reference, x, y)) ++inside;
    }
  }
  // Measured with Mesa llvmpipe: 1 pixel of 64,000 differs (an edge pixel). Allowed: 0.1%.
  EXPECT_EQ(inside, 0) << differing << " pixels differ, " << inside << " inside a primitive";
  EXPECT_LE(differing, 2 * w * 2 * h / 1000);
  // The pictures are not trivially equal: the objects are drawn (colourful pixels).
  int coloured = 0;
  for (int y = 0; y < 2 * h; ++y) {
    for (int x = 0; x < 2 * w; ++x) {
      const auto p = reference.at(x, y);
      if (std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 60) ++coloured;
    }
  }
  EXPECT_GT(coloured, 2000);
}

TEST(Tile, RendererRefusesATileOutsideItsWall) {
  RenderSettings settings;
  settings.width = 32;
  settings.height = 32;
  settings.tile = Tile{2, 0, 2, 2};
  const auto renderer = Renderer::create(settings);
  ASSERT_FALSE(renderer.ok());
  EXPECT_NE(renderer.error().message.find("tile"), std::string::npos);
}

// A camera looking along -z from (0, 1, 10), no tilt: the left column of a 2 x 1 wall sees
// x <= 0, the right one x >= 0, exactly (the split plane is x = 0).
TEST(ViewVolume, IsTheBoxAroundTheTilesFrustumToViewDepth) {
  Camera camera;
  camera.eye = {0.0, 1.0, 10.0};
  camera.target = {0.0, 1.0, 0.0};
  camera.fovYDegrees = 90.0;  // tan(45 degrees) = 1: the window at depth d is +-d (square tiles)
  const Frustum left = tileFrustum(camera, Tile{0, 0, 2, 1}, 100, 200);
  const auto volume = viewVolume(camera, left, 8.0, std::nullopt);
  ASSERT_TRUE(volume);
  EXPECT_NEAR(volume->min[0], -8.0, 1e-9);  // at depth 8 the window spans x in [-8, 8]
  EXPECT_NEAR(volume->max[0], 0.0, 1e-9);
  EXPECT_NEAR(volume->min[1], 1.0 - 8.0, 1e-9);
  EXPECT_NEAR(volume->max[1], 1.0 + 8.0, 1e-9);
  EXPECT_NEAR(volume->min[2], 2.0, 1e-9);                      // 10 - view depth
  EXPECT_NEAR(volume->max[2], 10.0 - camera.nearPlane, 1e-9);  // the near plane
  // Within a box: the smallest box around (frustum piece ∩ box), here the part of the box
  // x <= 0 in front of the camera, tighter than cutting the frustum's box by it.
  const msg::Aabb scene{{-3.0, 0.0, -2.0}, {3.0, 2.0, 2.0}};
  const auto clipped = viewVolume(camera, left, 30.0, scene);
  ASSERT_TRUE(clipped);
  EXPECT_NEAR(clipped->min[0], -3.0, 1e-9);
  EXPECT_NEAR(clipped->max[0], 0.0, 1e-9);
  EXPECT_NEAR(clipped->min[1], 0.0, 1e-9);
  EXPECT_NEAR(clipped->max[1], 2.0, 1e-9);
  EXPECT_NEAR(clipped->min[2], -2.0, 1e-9);
  EXPECT_NEAR(clipped->max[2], 2.0, 1e-9);
  // A tile looking away from the box, or a box beyond view depth: nothing.
  EXPECT_FALSE(viewVolume(camera, left, 5.0, scene));
  EXPECT_FALSE(viewVolume(camera, left, 30.0, msg::Aabb{{1.0, 0.0, -2.0}, {3.0, 2.0, 2.0}}));
}

// Looking down at 45 degrees, the top row's frustum within a slab y in [0, 1] reaches only the
// far part of the slab: its box starts where the row's lowest ray leaves the slab, not at the
// camera.
TEST(ViewVolume, ClippingToTheSceneKeepsRowsOfATiltedViewApart) {
  Camera camera;
  camera.eye = {0.0, 5.0, 5.0};
  camera.target = {0.0, 0.0, 0.0};
  camera.fovYDegrees = 30.0;
  const msg::Aabb slab{{-10.0, 0.0, -10.0}, {10.0, 1.0, 10.0}};
  const auto top = viewVolume(camera, tileFrustum(camera, Tile{0, 0, 1, 2}, 100, 50), 40, slab);
  const auto bottom = viewVolume(camera, tileFrustum(camera, Tile{0, 1, 1, 2}, 100, 50), 40, slab);
  ASSERT_TRUE(top && bottom);
  // The row split ray goes through the target: it crosses y = 1 at z = 1 and y = 0 at z = 0.
  EXPECT_NEAR(top->max[2], 1.0, 1e-9);
  EXPECT_NEAR(bottom->min[2], 0.0, 1e-9);
  // The top row's upper ray (30 degrees down) meets y = 0 at z = 5 - 5 / tan 30; the bottom
  // row's lower ray (60 degrees down) meets y = 1 at z = 5 - 4 / tan 60.
  EXPECT_NEAR(top->min[2], 5.0 - 5.0 * std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(bottom->max[2], 5.0 - 4.0 / std::sqrt(3.0), 1e-9);
}

int colouredPixels(const Image& image) {
  int coloured = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto p = image.at(x, y);
      if (std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 60) ++coloured;
    }
  }
  return coloured;
}

// A routed viewer draws only what meets its volume: the route stops updating an object that
// leaves it, so the viewer's copy is stale.
TEST(ViewVolume, RenderingWithinABoxLeavesOutObjectsWhoseBoundsMissIt) {
  SceneCache scene;
  feed(scene, [](msg::MessageBuilder& b) {
    addShape(b, 101, msg::Shape::box({0.5, 0.5, 0.5}));
    for (const double x : {-1.5, 1.5}) {
      b.addObject(x < 0 ? 1 : 2, msg::rigidType(), msg::ObjectOp::Add)
          .set(msg::RigidParam::kPosition, msg::Vec3{x, 0.5, 0.0})
          .set(msg::RigidParam::kOrientation, msg::Quat{0, 0, 0, 1})
          .set(msg::RigidParam::kBounds, msg::Aabb{{x - 0.5, 0.0, -0.5}, {x + 0.5, 1.0, 0.5}})
          .set(msg::RigidParam::kShape, std::uint64_t{101});
    }
  });
  ASSERT_TRUE(scene.find(1) && scene.find(1)->bounds);
  RenderSettings settings;
  settings.width = 160;
  settings.height = 100;
  settings.supersample = 1;
  auto renderer = Renderer::create(settings);
  ASSERT_TRUE(renderer.ok());
  const msg::Aabb left{{-10.0, -1.0, -10.0}, {0.0, 5.0, 10.0}};
  const msg::Aabb nothing{{1e9, 1e9, 1e9}, {-1e9, -1e9, -1e9}};
  const auto all = renderer->render(scene, wallCamera());
  const auto some = renderer->render(scene, wallCamera(), &left);
  const auto none = renderer->render(scene, wallCamera(), &nothing);
  ASSERT_TRUE(all.ok() && some.ok() && none.ok());
  EXPECT_GT(colouredPixels(*some), 200);
  EXPECT_GT(colouredPixels(*all), colouredPixels(*some) + 200);
  EXPECT_EQ(colouredPixels(*none), 0);
}

TEST(ViewVolume, BoxesAreParsedAndWrittenInTheRouteFiltersFormat) {
  const auto box = parseBox("-3 -1.5 -2 3, 2.5, 2");
  ASSERT_TRUE(box.ok());
  EXPECT_EQ(*box, (msg::Aabb{{-3.0, -1.5, -2.0}, {3.0, 2.5, 2.0}}));
  EXPECT_EQ(formatBox(*box), "-3 -1.5 -2 3 2.5 2");
  EXPECT_FALSE(parseBox("1 2 3 4 5").ok());
  EXPECT_FALSE(parseBox("0 0 0 1 1 nan").ok());
  EXPECT_NE(parseBox("1 0 0 0 1 1").error().message.find("min <= max"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::viewer
