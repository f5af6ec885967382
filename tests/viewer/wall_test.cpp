// The wall description: head-coupled off-axis frusta against the analytic projection through the
// wall, mullions hiding what is behind them, blend ramps summing to one, the file format.
#include "vrflow/viewer/wall.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scene_messages.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/viewer/renderer.hpp"

namespace vrflow::viewer {
namespace {

// A 2 x 2 wall of 1.6 x 0.9 m screens with 5 cm mullions, centred 1.5 m up at z = 0 and facing
// +z; 160 x 90 pixels per tile (1 cm per pixel).
const char* kWall = R"(# the test wall
grid 2 2
pixels 160 90
size 1.6 0.9
bezel 0.05 0.05
centre 0 1.5 0
right 1 0 0
up 0 1 0
eye 0.2 1.4 2.5
tile tl 0 0 local :0.0 0 0
tile tr 1 0 local :0.1 0 0
tile bl 0 1 local :0.2 0 0
tile br 1 1 local :0.3 fullscreen
)";

Wall testWall() {
  auto wall = parseWall(kWall, "test.wall");
  EXPECT_TRUE(wall.ok()) << wall.error().message;
  return *wall;
}

// Where the line from `eye` through `point` meets the wall plane z = 0, in metres from the
// wall's centre (u right, v up).
std::pair<double, double> throughWall(const msg::Vec3& eye, const msg::Vec3& point) {
  const double t = eye[2] / (eye[2] - point[2]);
  return {eye[0] + t * (point[0] - eye[0]), eye[1] + t * (point[1] - eye[1]) - 1.5};
}

// The pixel (continuous, from the top-left) where glFrustum(f) after gluLookAt(camera) puts a
// world point: the pipeline the renderer sets up, written out.
std::pair<double, double> projected(const TileView& view, const msg::Vec3& p, int w, int h) {
  const ViewBasis b = viewBasis(view.camera);
  const msg::Vec3 d{p[0] - view.camera.eye[0], p[1] - view.camera.eye[1],
                    p[2] - view.camera.eye[2]};
  const auto dot = [](const msg::Vec3& a, const msg::Vec3& c) {
    return a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
  };
  const double depth = dot(d, b.forward);
  const double x = dot(d, b.side) * view.frustum.nearPlane / depth;
  const double y = dot(d, b.up) * view.frustum.nearPlane / depth;
  const auto& f = view.frustum;
  return {(x - f.left) / (f.right - f.left) * w, (f.top - y) / (f.top - f.bottom) * h};
}

TEST(Wall, HeadCoupledFrustumPutsEveryPointWhereItsLineOfSightCrossesTheWall) {
  const Wall wall = testWall();
  const msg::Vec3 eyes[] = {{0.2, 1.4, 2.5}, {-1.3, 2.2, 1.0}, {2.0, 0.5, 0.4}};
  const msg::Vec3 points[] = {
      {0.4, 1.0, -3.0}, {-2.0, 2.5, -1.0}, {1.1, 0.3, -8.0}, {-0.5, 1.9, 0.5}};
  int checked = 0;
  for (const auto& eye : eyes) {
    for (const auto& point : points) {
      if (point[2] >= eye[2]) continue;
      const auto [u, v] = throughWall(eye, point);
      for (const auto& tile : wall.tiles) {
        const TileRect r = tileRect(wall, tile.col, tile.row);
        const double u0 = r.lowerLeft[0], u1 = r.lowerRight[0];
        const double v0 = r.lowerLeft[1] - 1.5, v1 = r.upperLeft[1] - 1.5;
        if (u < u0 || u > u1 || v < v0 || v > v1) continue;
        auto view = tileView(wall, tile.col, tile.row, eye);
        ASSERT_TRUE(view.ok()) << view.error().message;
        const auto [px, py] = projected(*view, point, wall.pixelsX, wall.pixelsY);
        EXPECT_NEAR(px, (u - u0) / wall.sizeX * wall.pixelsX, 1e-9) << tile.id;
        EXPECT_NEAR(py, (v1 - v) / wall.sizeY * wall.pixelsY, 1e-9) << tile.id;
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 8);
}

// A small sphere (a `point` object) drawn by the renderer through a tile's head-coupled view
// lands, to the pixel, where the analytic projection says.
TEST(Wall, RenderedPointLandsOnThePixelItsLineOfSightCrosses) {
  const Wall wall = testWall();
  const msg::Vec3 eye{-0.7, 1.9, 1.8};
  const msg::Vec3 point{2.3, 2.0, -1.8};  // seen through (0.8, 1.95, 0): tile tr
  SceneCache scene;
  testing::feed(scene, [&](msg::MessageBuilder& b) {
    b.addObject(5, msg::pointType(), msg::ObjectOp::Add).set(msg::PointParam::kPosition, point);
  });
  const auto [u, v] = throughWall(eye, point);
  const WallTile& tile = *wall.find(u > 0 ? (v > 0 ? "tr" : "br") : (v > 0 ? "tl" : "bl"));
  const TileRect r = tileRect(wall, tile.col, tile.row);
  const double ex = (u - r.lowerLeft[0]) / wall.sizeX * wall.pixelsX;
  const double ey = (r.upperLeft[1] - 1.5 - v) / wall.sizeY * wall.pixelsY;
  RenderSettings settings;
  settings.width = wall.pixelsX;
  settings.height = wall.pixelsY;
  settings.ground = false;
  settings.pointRadius = 0.05;
  auto renderer = Renderer::create(settings);
  ASSERT_TRUE(renderer.ok());
  auto view = tileView(wall, tile.col, tile.row, eye);
  ASSERT_TRUE(view.ok());
  auto image = renderer->render(scene, view->camera, view->frustum);
  ASSERT_TRUE(image.ok()) << image.error().message;
  double sx = 0, sy = 0;
  int n = 0;
  for (int y = 0; y < image->height; ++y) {
    for (int x = 0; x < image->width; ++x) {
      const auto p = image->at(x, y);
      if (std::abs(p[0] - 204) + std::abs(p[1] - 219) + std::abs(p[2] - 237) < 30) continue;
      sx += x + 0.5, sy += y + 0.5, ++n;
    }
  }
  ASSERT_GT(n, 4);
  EXPECT_NEAR(sx / n, ex, 0.5);
  EXPECT_NEAR(sy / n, ey, 0.5);
}

// Pixels drawn for a sphere sitting in the wall plane, seen from `eye` through every tile.
int pixelsOnAnyTile(const Wall& wall, const msg::Vec3& at, const msg::Vec3& eye) {
  SceneCache scene;
  testing::feed(scene, [&](msg::MessageBuilder& b) {
    b.addObject(5, msg::pointType(), msg::ObjectOp::Add).set(msg::PointParam::kPosition, at);
  });
  RenderSettings settings;
  settings.width = wall.pixelsX;
  settings.height = wall.pixelsY;
  settings.ground = false;
  settings.supersample = 1;
  settings.pointRadius = 0.02;  // smaller than half the 5 cm mullion
  auto renderer = Renderer::create(settings);
  int drawn = 0;
  for (const auto& tile : wall.tiles) {
    auto view = tileView(wall, tile.col, tile.row, eye);
    auto image = renderer->render(scene, view->camera, view->frustum);
    for (int y = 0; y < image->height; ++y) {
      for (int x = 0; x < image->width; ++x) {
        const auto p = image->at(x, y);
        if (std::abs(p[0] - 204) + std::abs(p[1] - 219) + std::abs(p[2] - 237) > 30) ++drawn;
      }
    }
  }
  return drawn;
}

// Bezel compensation: the tiles show the world as through a window with mullions, so what lies
// behind a mullion is on no tile, and the same object beside it is.
TEST(Wall, WhatIsBehindAMullionIsOnNoTile) {
  const Wall wall = testWall();
  const msg::Vec3 eye{0.0, 1.5, 2.0};
  EXPECT_EQ(pixelsOnAnyTile(wall, {0.0, 1.2, 0.0}, eye), 0);   // vertical mullion
  EXPECT_EQ(pixelsOnAnyTile(wall, {-0.8, 1.5, 0.0}, eye), 0);  // horizontal mullion
  EXPECT_EQ(pixelsOnAnyTile(wall, {0.0, 1.5, 0.0}, eye), 0);   // where they cross
  EXPECT_GT(pixelsOnAnyTile(wall, {0.06, 1.2, 0.0}, eye), 4);  // beside the mullion
  EXPECT_GT(pixelsOnAnyTile(wall, {-0.8, 1.56, 0.0}, eye), 4);
}

Wall projectorWall(double gamma) {
  auto wall = parseWall(R"(grid 3 2
pixels 100 80
size 1.0 0.8
overlap 0.2 0.1
gamma )" + std::to_string(gamma) +
                            R"(
tile a 0 0 h :0 0 0
tile b 1 0 h :0 0 0
tile c 2 0 h :0 0 0
tile d 0 1 h :0 0 0
tile e 1 1 h :0 0 0
tile f 2 1 h :0 0 0
)",
                        "projectors.wall");
  EXPECT_TRUE(wall.ok()) << wall.error().message;
  return *wall;
}

TEST(Wall, BlendWeightsOfOverlappingProjectorsSumToOneEverywhereOnTheWall) {
  const Wall wall = projectorWall(1.0);
  // The wall spans 3 * 1.0 - 2 * 0.2 = 2.6 m by 2 * 0.8 - 0.1 = 1.5 m.
  int inOverlap = 0;
  for (double u = -1.299; u < 1.3; u += 0.0173) {
    for (double v = -0.749; v < 0.75; v += 0.0131) {
      double sum = 0;
      int covering = 0;
      for (const auto& t : wall.tiles) {
        const double w = blendWeight(wall, t.col, t.row, u, v);
        EXPECT_GE(w, 0.0);
        EXPECT_LE(w, 1.0);
        sum += w;
        covering += w > 0 ? 1 : 0;
      }
      EXPECT_NEAR(sum, 1.0, 1e-12) << u << " " << v;
      if (covering > 1) ++inOverlap;
    }
  }
  EXPECT_GT(inOverlap, 1000);
}

// The masks themselves, at pixel centres that coincide on the wall (1 cm pixels, overlaps of
// 20 and 10 pixels): neighbours' bytes sum to 255 (+-1 rounding) at gamma 1.
TEST(Wall, BlendMasksOfNeighboursSumToFullBrightness) {
  const Wall wall = projectorWall(1.0);
  const auto a = blendMask(wall, 0, 0), b = blendMask(wall, 1, 0), d = blendMask(wall, 0, 1),
             e = blendMask(wall, 1, 1);
  ASSERT_EQ(a.size(), 100u * 80u);
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 100; ++x) {
      const auto at = [](const std::vector<std::uint8_t>& m, int i, int j) {
        return (i < 0 || j < 0 || i >= 100 || j >= 80) ? 0 : int{m[j * 100 + i]};
      };
      // Pixel (x, y) of a; b starts 80 pixels to the right, d 70 pixels down.
      const int sum = at(a, x, y) + at(b, x - 80, y) + at(d, x, y - 70) + at(e, x - 80, y - 70);
      EXPECT_NEAR(sum, 255, 2) << x << " " << y;
    }
  }
  EXPECT_EQ(a[40 * 100 + 40], 255);  // inside: untouched
  EXPECT_EQ(a[40 * 100 + 99], 0);    // its last column is the neighbour's first ramp pixel
  // Gamma 2.2: the bytes are weight^(1/2.2), brighter than linear in the ramp.
  const auto g = blendMask(projectorWall(2.2), 0, 0);
  EXPECT_GT(g[40 * 100 + 90], a[40 * 100 + 90]);
}

// The renderer multiplies its frame by the mask: the background colour scaled per pixel.
TEST(Wall, TheRendererDarkensTheOverlapByTheMask) {
  const Wall wall = projectorWall(1.0);
  RenderSettings settings;
  settings.width = wall.pixelsX;
  settings.height = wall.pixelsY;
  settings.ground = false;
  settings.background = {1.0f, 1.0f, 1.0f};
  settings.blendMask = blendMask(wall, 1, 0);
  for (const int k : {1, 2}) {
    settings.supersample = k;
    auto renderer = Renderer::create(settings);
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    auto view = tileView(wall, 1, 0, wall.eye);
    auto image = renderer->render(SceneCache(), view->camera, view->frustum);
    ASSERT_TRUE(image.ok());
    for (int y = 0; y < 80; ++y) {
      for (int x = 0; x < 100; ++x) {
        EXPECT_NEAR(image->at(x, y)[0], settings.blendMask[y * 100 + x], 1) << x << " " << y;
      }
    }
  }
  settings.blendMask.pop_back();
  EXPECT_FALSE(Renderer::create(settings).ok());
}

TEST(Wall, FileErrorsNameTheFileAndLine) {
  const auto error = [](const std::string& text) {
    auto wall = parseWall(text, "lab.wall");
    return wall.ok() ? std::string("(parsed)") : wall.error().message;
  };
  EXPECT_EQ(error("grid 2 2\nsize 1 x\n").rfind("lab.wall:2: 'size' expects", 0), 0u);
  EXPECT_EQ(error("grid 2 2\n\nwobble 3\n").rfind("lab.wall:3: unknown key 'wobble'", 0), 0u);
  EXPECT_EQ(error("grid 2 2\ntile a 0 0 h :0 0 0\ntile a 1 0 h :0 0 0\n"),
            "lab.wall:3: tile 'a' declared twice");
  EXPECT_EQ(error("grid 2 2\ntile a 0 0 h :0 0 0\ntile b 0 0 h :0 0 0\n"),
            "lab.wall:3: two tiles at column 0, row 0");
  EXPECT_EQ(error("grid 2 2\ntile a 2 0 h :0 0 0\n"),
            "lab.wall:2: tile 'a' is outside the 2 x 2 grid");
  EXPECT_EQ(error("grid 2 2\nbezel 0.1 0\noverlap 0.1 0\ntile a 0 0 h :0 fullscreen\n"),
            "lab.wall: a wall has either a bezel or an overlap along an axis, not both");
  EXPECT_EQ(error("grid 2 2\nright 1 0 0\nup 1 0 0\ntile a 0 0 h :0 0 0\n"),
            "lab.wall: 'right' and 'up' must be orthogonal unit vectors");
  EXPECT_EQ(error("grid 2 2\n"), "lab.wall: no 'tile' line");
  EXPECT_EQ(error("grid 2 2\ntile a 0 0 h :0 fullscreen extra\n").rfind("lab.wall:2:", 0), 0u);
  EXPECT_NE(loadWall("/nonexistent/x.wall").error().message.find("/nonexistent/x.wall"),
            std::string::npos);
  // An eye behind the wall has no view through it.
  const Wall wall = testWall();
  const auto behind = tileView(wall, 0, 0, {0, 1.5, -1});
  ASSERT_FALSE(behind.ok());
  EXPECT_NE(behind.error().message.find("in front of the wall"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::viewer
