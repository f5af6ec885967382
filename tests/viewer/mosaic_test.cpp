// The wall recorder's mosaic: tiles joined where they sit equal one view through the whole
// wall, blended projector overlaps add up to it, mullions stay black.
#include "vrflow/viewer/mosaic.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "vrflow/viewer/renderer.hpp"
#include "wall_scene.hpp"

namespace vrflow::viewer {
namespace {

// The wall in front of the test scene (plane z = 2, facing +z), seen from an eye off its axis.
Wall wallOf(const std::string& lines) {
  auto wall =
      parseWall("centre 0 1.2 2\nright 1 0 0\nup 0 1 0\neye 0.3 1.7 6\n" + lines, "mosaic.wall");
  EXPECT_TRUE(wall.ok()) << wall.error().message;
  return *wall;
}

Image draw(const Wall& wall, int col, int row, bool blend) {
  RenderSettings settings;
  settings.width = wall.pixelsX;
  settings.height = wall.pixelsY;
  settings.supersample = 1;
  if (blend) settings.blendMask = blendMask(wall, col, row);
  auto renderer = Renderer::create(settings);
  EXPECT_TRUE(renderer.ok()) << renderer.error().message;
  const auto view = tileView(wall, col, row, wall.eye);
  EXPECT_TRUE(view.ok());
  auto image = renderer->render(testing::wallScene(), view->camera, view->frustum);
  EXPECT_TRUE(image.ok());
  return *image;
}

Image mosaicOf(const Wall& wall, bool blend) {
  std::vector<PlacedImage> tiles;
  for (const auto& t : wall.tiles) tiles.push_back({t.col, t.row, draw(wall, t.col, t.row, blend)});
  auto mosaic = stitchWall(wall, tiles);
  EXPECT_TRUE(mosaic.ok()) << mosaic.error().message;
  return *mosaic;
}

const char* kTiles =
    "tile a 0 0 h :0 0 0\ntile b 1 0 h :0 0 0\ntile c 0 1 h :0 0 0\ntile d 1 1 h :0 0 0\n";

struct Difference {
  int differing = 0;  // pixels with a channel further than `tolerance` apart
  int inside = 0;     // of which not on an edge of the reference
  int coloured = 0;   // object pixels in the reference
};

Difference compare(const Image& a, const Image& reference, int tolerance) {
  Difference d;
  for (int y = 0; y < reference.height; ++y) {
    for (int x = 0; x < reference.width; ++x) {
      const auto p = a.at(x, y), q = reference.at(x, y);
      if (std::max({q[0], q[1], q[2]}) - std::min({q[0], q[1], q[2]}) > 60) ++d.coloured;
      bool differs = false;
      for (int c = 0; c < 3; ++c) differs |= std::abs(int{p[c]} - int{q[c]}) > tolerance;
      if (!differs) continue;
      ++d.differing;
      if (!testing::onAnEdge(reference, x, y)) ++d.inside;
    }
  }
  return d;
}

TEST(Mosaic, TheTilesOfAWallJoinIntoTheViewThroughOneScreenOfTheWholeSize) {
  const Wall wall = wallOf(std::string("grid 2 2\npixels 160 90\nsize 1.6 0.9\n") + kTiles);
  const Wall whole = wallOf("grid 1 1\npixels 320 180\nsize 3.2 1.8\ntile w 0 0 h :0 0 0\n");
  const Image mosaic = mosaicOf(wall, false);
  const Image reference = draw(whole, 0, 0, false);
  ASSERT_EQ(mosaic.width, 320);
  ASSERT_EQ(mosaic.height, 180);
  const Difference d = compare(mosaic, reference, 0);
  RecordProperty("differing_pixels", d.differing);
  EXPECT_EQ(d.inside, 0) << d.differing;
  EXPECT_LE(d.differing, 320 * 180 / 1000);
  EXPECT_GT(d.coloured, 2000);
}

// Projectors overlapping by 20 and 10 pixels, each dimmed by its blend ramps: the light they add
// up to on the wall is the whole view, to rounding (each tile rounds its dimmed pixel once).
TEST(Mosaic, BlendedProjectorOverlapsAddUpToTheWholeView) {
  const Wall wall = wallOf(std::string("grid 2 2\npixels 160 90\nsize 1.6 0.9\n"
                                       "overlap 0.2 0.1\n") +
                           kTiles);
  const Wall whole = wallOf("grid 1 1\npixels 300 170\nsize 3.0 1.7\ntile w 0 0 h :0 0 0\n");
  const Image mosaic = mosaicOf(wall, true);
  const Image reference = draw(whole, 0, 0, false);
  ASSERT_EQ(mosaic.width, 300);
  ASSERT_EQ(mosaic.height, 170);
  const Difference d = compare(mosaic, reference, 3);
  RecordProperty("differing_pixels", d.differing);
  EXPECT_EQ(d.inside, 0) << d.differing;
  EXPECT_LE(d.differing, 300 * 170 / 1000);
  // Without the ramps the overlaps would be about twice as bright: the blend is what matters.
  const Difference unblended = compare(mosaicOf(wall, false), reference, 3);
  EXPECT_GT(unblended.differing, 20 * 170);
}

TEST(Mosaic, MullionsAreBlackAndTheTilesSitBesideThem) {
  const Wall wall = wallOf(std::string("grid 2 2\npixels 160 90\nsize 1.6 0.9\n"
                                       "bezel 0.05 0.03\n") +
                           kTiles);
  const Image mosaic = mosaicOf(wall, false);
  ASSERT_EQ(mosaic.width, 2 * 160 + 5);
  ASSERT_EQ(mosaic.height, 2 * 90 + 3);
  for (int y = 0; y < mosaic.height; ++y) {
    for (int x = 160; x < 165; ++x) EXPECT_EQ(mosaic.at(x, y), (std::array<std::uint8_t, 3>{}));
  }
  for (int x = 0; x < mosaic.width; ++x) {
    for (int y = 90; y < 93; ++y) EXPECT_EQ(mosaic.at(x, y), (std::array<std::uint8_t, 3>{}));
  }
  const Image d = draw(wall, 1, 1, false);
  EXPECT_EQ(mosaic.at(165, 93), d.at(0, 0));
  EXPECT_EQ(mosaic.at(mosaic.width - 1, mosaic.height - 1), d.at(159, 89));
}

TEST(Mosaic, ATileOfAnotherSizeIsRefused) {
  const Wall wall = wallOf(std::string("grid 2 2\npixels 160 90\nsize 1.6 0.9\n") + kTiles);
  Image small;
  small.width = 16;
  small.height = 9;
  small.rgb.resize(16 * 9 * 3);
  const auto mosaic = stitchWall(wall, {{0, 0, small}});
  ASSERT_FALSE(mosaic.ok());
  EXPECT_NE(mosaic.error().message.find("16x9"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::viewer
