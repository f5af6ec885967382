// Rendered pixels against the analytic projection of known scenes.
#include "vrflow/viewer/renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "scene_messages.hpp"

namespace vrflow::viewer {
namespace {

using testing::addNet;
using testing::addRigid;
using testing::addShape;
using testing::feed;

constexpr int kWidth = 320;
constexpr int kHeight = 240;
constexpr double kPi = 3.14159265358979323846;

// The camera of every test: at height 1 looking along -z, horizontal.
Camera testCamera() {
  Camera camera;
  camera.eye = {0.0, 1.0, 10.0};
  camera.target = {0.0, 1.0, 0.0};
  camera.up = {0.0, 1.0, 0.0};
  camera.fovYDegrees = 45.0;
  return camera;
}

// Where a world point lands in the image (column, row from the top), by the pinhole model.
std::array<double, 2> project(const msg::Vec3& p) {
  const Camera c = testCamera();
  const double depth = c.eye[2] - p[2];  // the camera looks along -z
  const double focal = (kHeight / 2.0) / std::tan(c.fovYDegrees * kPi / 360.0);
  return {kWidth / 2.0 + focal * (p[0] - c.eye[0]) / depth,
          kHeight / 2.0 - focal * (p[1] - c.eye[1]) / depth};
}

RenderSettings settings(bool ground = false) {
  RenderSettings s;
  s.width = kWidth;
  s.height = kHeight;
  s.ground = ground;
  s.shadows = false;
  return s;
}

Image render(const SceneCache& scene, const RenderSettings& s) {
  auto renderer = Renderer::create(s);
  EXPECT_TRUE(renderer.ok()) << renderer.error().message;
  EXPECT_NE(renderer->description().find("OpenGL"), std::string::npos);
  auto image = renderer->render(scene, testCamera());
  EXPECT_TRUE(image.ok()) << image.error().message;
  return *image;
}

std::array<int, 3> bytesOf(const std::array<float, 3>& c, float intensity = 1.0f) {
  return {static_cast<int>(std::lround(c[0] * intensity * 255.0f)),
          static_cast<int>(std::lround(c[1] * intensity * 255.0f)),
          static_cast<int>(std::lround(c[2] * intensity * 255.0f))};
}

// Pixel (x, y) is `expected` within `tolerance` per channel.
::testing::AssertionResult pixelIs(const Image& image, int x, int y, std::array<int, 3> expected,
                                   int tolerance = 2) {
  const auto p = image.at(x, y);
  for (int c = 0; c < 3; ++c) {
    if (std::abs(static_cast<int>(p[c]) - expected[c]) > tolerance) {
      return ::testing::AssertionFailure()
             << "pixel (" << x << ", " << y << ") is " << int(p[0]) << " " << int(p[1]) << " "
             << int(p[2]) << ", expected " << expected[0] << " " << expected[1] << " "
             << expected[2];
    }
  }
  return ::testing::AssertionSuccess();
}

// The brightness factor the fixed lights give a surface facing +z (towards the camera).
float facingCameraIntensity() {
  const auto& k = kLighting.keyDirection;
  const float keyDot = k[2] / std::sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
  return kLighting.ambient + kLighting.key * std::max(0.0f, keyDot);  // the fill comes from -z
}

TEST(Renderer, EmptySceneWithoutGroundIsBackgroundEverywhere) {
  SceneCache scene;
  const auto s = settings();
  const Image image = render(scene, s);
  ASSERT_EQ(image.width, kWidth);
  ASSERT_EQ(image.height, kHeight);
  for (int y = 0; y < kHeight; y += 7) {
    for (int x = 0; x < kWidth; x += 7) ASSERT_TRUE(pixelIs(image, x, y, bytesOf(s.background), 1));
  }
}

TEST(Renderer, GroundIsVisibleBelowTheHorizonOnly) {
  SceneCache scene;
  auto s = settings(true);
  const Image image = render(scene, s);
  // The ground's far edge (z = -20) is the highest ground row; above it only background.
  const int farEdgeRow = static_cast<int>(std::ceil(project({0.0, 0.0, -s.groundHalfSize})[1]));
  for (int x = 0; x < kWidth; x += 5) {
    for (int y = 0; y < farEdgeRow - 1; y += 3) {
      ASSERT_TRUE(pixelIs(image, x, y, bytesOf(s.background), 1));
    }
    // Below: lit checker squares (grey, darker than their base colour, never background).
    for (int y = farEdgeRow + 2; y < kHeight; y += 3) {
      const auto p = image.at(x, y);
      ASSERT_NEAR(p[0], p[1], 3) << x << "," << y;
      ASSERT_LT(p[0], 0.8 * 255) << x << "," << y;
      ASSERT_GT(p[0], 0.3 * 255) << x << "," << y;
    }
  }
}

TEST(Renderer, BoxCoversItsProjectionLitByTheFixedLights) {
  SceneCache scene;
  const msg::Vec3 centre{2.0, 1.0, 0.0};
  const double h = 0.5;
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::box({h, h, h}));
    addRigid(b, 7, centre, 100);
  }));
  const auto s = settings();
  const Image image = render(scene, s);
  // The front face (z = +h) spans these pixels; its inside shows the lit object colour.
  const auto topLeft = project({centre[0] - h, centre[1] + h, centre[2] + h});
  const auto bottomRight = project({centre[0] + h, centre[1] - h, centre[2] + h});
  const auto lit = bytesOf(objectColour(7), facingCameraIntensity());
  for (int y = static_cast<int>(topLeft[1]) + 2; y < bottomRight[1] - 2; y += 2) {
    for (int x = static_cast<int>(topLeft[0]) + 2; x < bottomRight[0] - 2; x += 2) {
      ASSERT_TRUE(pixelIs(image, x, y, lit, 3));
    }
  }
  // Every corner of the box projects inside this rectangle; 2 pixels outside it is background.
  double minX = 1e9, maxX = -1e9, minY = 1e9, maxY = -1e9;
  for (int corner = 0; corner < 8; ++corner) {
    const auto p =
        project({centre[0] + ((corner & 1) ? h : -h), centre[1] + ((corner & 2) ? h : -h),
                 centre[2] + ((corner & 4) ? h : -h)});
    minX = std::min(minX, p[0]), maxX = std::max(maxX, p[0]);
    minY = std::min(minY, p[1]), maxY = std::max(maxY, p[1]);
  }
  const auto background = bytesOf(s.background);
  const int row = static_cast<int>(centre[1]);
  for (int y = static_cast<int>(minY) + 2; y < maxY - 2; ++y) {
    ASSERT_TRUE(pixelIs(image, static_cast<int>(minX) - 2, y, background, 1));
    ASSERT_TRUE(pixelIs(image, static_cast<int>(maxX) + 2, y, background, 1));
  }
  for (int x = static_cast<int>(minX) + 2; x < maxX - 2; ++x) {
    ASSERT_TRUE(pixelIs(image, x, static_cast<int>(minY) - 2, background, 1));
    ASSERT_TRUE(pixelIs(image, x, static_cast<int>(maxY) + 2, background, 1));
  }
  (void)row;
}

TEST(Renderer, SphereSilhouetteMatchesItsAngularRadius) {
  SceneCache scene;
  const msg::Vec3 centre{-2.0, 1.0, 0.0};
  const double radius = 0.6;
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    addShape(b, 200, msg::Shape::sphere(radius));
    addRigid(b, 8, centre, 200);
  }));
  const auto s = settings();
  const Image image = render(scene, s);
  const auto c = project(centre);
  // The silhouette along the vertical through the centre: the tangent cone's half angle.
  const double distance = std::sqrt(centre[0] * centre[0] + 100.0);
  const double focal = (kHeight / 2.0) / std::tan(22.5 * kPi / 180.0);
  const double halfAngle = std::asin(radius / distance);
  // Along the view ray the depth is `distance` while the pinhole scales by the z depth only.
  const double extent = focal * std::tan(halfAngle) * distance / 10.0;
  const int cx = static_cast<int>(std::lround(c[0]));
  const int cy = static_cast<int>(std::lround(c[1]));
  const auto colour = objectColour(8);
  const auto inside = image.at(cx, cy);
  // The centre faces the camera: lit, in the object's hue.
  const double pixelSum = static_cast<double>(inside[0] + inside[1] + inside[2]);
  const double colourSum = double{colour[0]} + colour[1] + colour[2];
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(inside[k] / pixelSum, colour[k] / colourSum, 0.02);
  }
  const auto background = bytesOf(s.background);
  EXPECT_FALSE(pixelIs(image, cx, cy - static_cast<int>(extent) + 2, background, 1));
  EXPECT_FALSE(pixelIs(image, cx, cy + static_cast<int>(extent) - 2, background, 1));
  EXPECT_TRUE(pixelIs(image, cx, cy - static_cast<int>(extent) - 3, background, 1));
  EXPECT_TRUE(pixelIs(image, cx, cy + static_cast<int>(extent) + 3, background, 1));
}

TEST(Renderer, OrientationQuaternionTurnsTheShape) {
  // A rod along x, turned a quarter turn about z (x y z w order): it stands along y.
  SceneCache scene;
  const double s = std::sqrt(0.5);
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::box({1.5, 0.2, 0.2}));
    addRigid(b, 9, {0.0, 1.0, 0.0}, 100, {0.0, 0.0, s, s});
  }));
  const auto bg = settings();
  const Image image = render(scene, bg);
  const auto background = bytesOf(bg.background);
  for (const double y : {-0.3, 2.3}) {  // along the rod's new axis: covered
    const auto p = project({0.0, y, 0.2});
    EXPECT_FALSE(pixelIs(image, static_cast<int>(p[0]), static_cast<int>(p[1]), background, 1));
  }
  for (const double x : {-1.2, 1.2}) {  // where the unturned rod would be: empty
    const auto p = project({x, 1.0, 0.2});
    EXPECT_TRUE(pixelIs(image, static_cast<int>(p[0]), static_cast<int>(p[1]), background, 1));
  }
}

TEST(Renderer, NearObjectHidesFarObjectWhateverTheDrawingOrder) {
  for (const bool nearFirst : {true, false}) {
    SceneCache scene;
    const std::uint64_t nearId = nearFirst ? 1 : 2;
    const std::uint64_t farId = nearFirst ? 2 : 1;  // objects are drawn by ascending id
    ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
      addShape(b, 300, msg::Shape::box({0.3, 0.3, 0.3}));
      addShape(b, 301, msg::Shape::box({1.5, 1.5, 0.2}));
      addRigid(b, nearId, {0.0, 1.0, 4.0}, 300);
      addRigid(b, farId, {0.0, 1.0, -3.0}, 301);
    }));
    const Image image = render(scene, settings());
    const auto c = project({0.0, 1.0, 4.3});
    EXPECT_TRUE(pixelIs(image, static_cast<int>(c[0]), static_cast<int>(c[1]),
                        bytesOf(objectColour(nearId), facingCameraIntensity()), 3))
        << "near object drawn " << (nearFirst ? "first" : "last");
    // Beside the near box, the far plate shows.
    const auto side = project({1.0, 1.0, -2.8});
    EXPECT_TRUE(pixelIs(image, static_cast<int>(side[0]), static_cast<int>(side[1]),
                        bytesOf(objectColour(farId), facingCameraIntensity()), 3));
  }
}

TEST(Renderer, NetIsATwoSidedSurface) {
  SceneCache scene;
  // A vertical 2 x 2 quad at z = 0 whose triangles face away from the camera (-z).
  const std::vector<double> xyz{-1, 0.5, 0, 1, 0.5, 0, 1, 1.5, 0, -1, 1.5, 0};
  const std::vector<std::uint32_t> away{0, 2, 1, 0, 3, 2};
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) { addNet(b, 40, xyz, away); }));
  const Image image = render(scene, settings());
  const auto c = project({0.3, 1.0, 0.0});
  // Seen from its back, lit as if it faced the camera.
  EXPECT_TRUE(pixelIs(image, static_cast<int>(c[0]), static_cast<int>(c[1]),
                      bytesOf(objectColour(40), facingCameraIntensity()), 3));
  const auto outside = project({1.2, 1.0, 0.0});
  EXPECT_TRUE(pixelIs(image, static_cast<int>(outside[0]) + 2, static_cast<int>(outside[1]),
                      bytesOf(settings().background), 1));
}

TEST(Renderer, FluidParticlesArePointsOfTheParticleColour) {
  SceneCache scene;
  const std::vector<float> particles{0.0f, 1.0f, 0.0f, 1.0f, 2.0f, 0.0f};
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    b.addMesh(500, true, particles, {});
    b.addObject(50, msg::fluidType(), msg::ObjectOp::Add)
        .set(msg::FluidParam::kParticles, std::uint64_t{500});
  }));
  auto s = settings();
  s.particleSize = 5.0f;
  const Image image = render(scene, s);
  for (std::size_t i = 0; i < particles.size(); i += 3) {
    const auto p = project({particles[i], particles[i + 1], particles[i + 2]});
    EXPECT_TRUE(pixelIs(image, static_cast<int>(p[0]), static_cast<int>(p[1]),
                        bytesOf(s.particleColour), 1));
  }
}

TEST(Renderer, ShadowDarkensTheGroundUnderAnObject) {
  SceneCache scene;
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::box({0.5, 0.5, 0.5}));
    addRigid(b, 7, {0.0, 0.6, 0.0}, 100);
  }));
  auto s = settings(true);
  Camera above = testCamera();
  above.eye = {0.0, 12.0, 0.01};
  above.target = {0.0, 0.0, 0.0};
  auto withShadow = Renderer::create(s);
  s.shadows = true;
  auto renderer = Renderer::create(s);
  ASSERT_TRUE(renderer.ok() && withShadow.ok());
  s.shadows = false;
  auto plain = Renderer::create(s);
  const Image shadowed = *renderer->render(scene, above);
  const Image unshadowed = *plain->render(scene, above);
  // Seen from above (image up = -z): the key light comes from +x, +z, so the shadow falls
  // towards -x, -z, up to 0.5 m beyond the box's edge (its top is 1.1 m high); 24 pixels a metre.
  const int x = kWidth / 2 - 18, y = kHeight / 2 - 18;
  const auto a = shadowed.at(x, y), b = unshadowed.at(x, y);
  EXPECT_LT(a[0] + 20, b[0]) << "shadowed " << int(a[0]) << ", plain " << int(b[0]);
}

TEST(Renderer, SupersamplingKeepsColoursAndBlendsEdges) {
  SceneCache scene;
  const msg::Vec3 centre{2.0, 1.0, 0.0};
  ASSERT_TRUE(feed(scene, [&](msg::MessageBuilder& b) {
    addShape(b, 100, msg::Shape::box({0.5, 0.5, 0.5}));
    addRigid(b, 7, centre, 100);
  }));
  auto s = settings();
  s.supersample = 3;
  const Image image = render(scene, s);
  ASSERT_EQ(image.width, kWidth);
  const auto c = project({centre[0], centre[1], centre[2] + 0.5});
  EXPECT_TRUE(pixelIs(image, static_cast<int>(c[0]), static_cast<int>(c[1]),
                      bytesOf(objectColour(7), facingCameraIntensity()), 3));
  // Along the row through the centre, the top edge of the front face is crossed somewhere: some
  // pixel of the column above the centre is neither background nor face colour.
  const auto background = bytesOf(s.background);
  const auto face = bytesOf(objectColour(7), facingCameraIntensity());
  int blended = 0;
  for (int y = static_cast<int>(c[1]) - 30; y < c[1]; ++y) {
    const auto p = image.at(static_cast<int>(c[0]), y);
    const bool isBackground = pixelIs(image, static_cast<int>(c[0]), y, background, 1);
    const bool isFace = pixelIs(image, static_cast<int>(c[0]), y, face, 3);
    if (!isBackground && !isFace && p[2] <= std::max(background[2], face[2]) + 1) ++blended;
  }
  EXPECT_GE(blended, 1);
  s.supersample = 5;
  EXPECT_FALSE(Renderer::create(s).ok());
}

TEST(Renderer, RejectsAnImpossibleImageSize) {
  auto s = settings();
  s.width = 0;
  const auto renderer = Renderer::create(s);
  ASSERT_FALSE(renderer.ok());
  EXPECT_NE(renderer.error().message.find("image size"), std::string::npos);
}

TEST(ObjectColour, IsStablePerIdAndFarApartForASendersConsecutiveIds) {
  EXPECT_EQ(objectColour(42), objectColour(42));
  // Ids as Module::newId() hands them out on one host: consecutive counters.
  const std::uint64_t first = (std::uint64_t{0x7F000001} << 32) | 5;
  for (std::uint64_t a = first; a < first + 6; ++a) {
    for (const float c : objectColour(a)) {
      EXPECT_GE(c, 0.0f);
      EXPECT_LE(c, 1.0f);
    }
    for (std::uint64_t b = a + 1; b < first + 6; ++b) {
      const auto x = objectColour(a), y = objectColour(b);
      const float distance = std::abs(x[0] - y[0]) + std::abs(x[1] - y[1]) + std::abs(x[2] - y[2]);
      EXPECT_GT(distance, 0.15f) << "ids " << a << " and " << b;
    }
  }
}

}  // namespace
}  // namespace vrflow::viewer
