// Scene files and generators.
#include "vrflow/rigid/scene.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>

#include "process_helpers.hpp"

namespace vrflow::rigid {
namespace {

TEST(RigidScene, LoadsEveryShapeKindWithMassOrDensity) {
  const auto bodies = loadScene(testing::sourceDir() + "/tests/rigid/data/drop.json");
  ASSERT_TRUE(bodies) << bodies.error().message;
  ASSERT_EQ(bodies->size(), 4u);
  EXPECT_TRUE((*bodies)[0].kinematic);
  EXPECT_TRUE(std::isinf((*bodies)[0].mass));
  EXPECT_EQ((*bodies)[1].shape.kind, msg::ShapeKind::Sphere);
  EXPECT_EQ((*bodies)[1].mass, 1.5);
  EXPECT_EQ((*bodies)[1].linearVelocity, (Vec3{0.5, 0, 0}));
  EXPECT_NEAR((*bodies)[2].mass, 400 * 0.4 * 0.3 * 0.5, 1e-9);
  const double qn = std::sqrt(0.2 * 0.2 + 0.1 * 0.1 + 0.97 * 0.97);
  EXPECT_NEAR((*bodies)[2].orientation[3], 0.97 / qn, 1e-12);
  const Body& rock = (*bodies)[3];
  EXPECT_EQ(rock.shape.kind, msg::ShapeKind::ConvexHull);
  EXPECT_EQ(rock.shape.vertices.size(), 6u * 3u);
  EXPECT_EQ(rock.shape.indices.size(), 8u * 3u);  // 6 points in general position: 8 triangles
  // Recentred on the centroid: the hull's first moment about its origin vanishes, and the body
  // moved by the same amount, so the points stay where the file put them.
  const auto props = msg::massProperties(rock.shape, 1.0);
  EXPECT_GT(props.volume, 0);
  bool found = false;
  for (std::size_t i = 0; i < rock.shape.vertices.size(); i += 3) {
    const Eigen::Vector3d world = asEigen(rock.position) + msg::asVector3(&rock.shape.vertices[i]);
    if (std::abs(world[0] - (-1.0 + 0.2)) < 1e-9 && std::abs(world[1] - 0.6) < 1e-9 &&
        std::abs(world[2] + 0.5) < 1e-9)
      found = true;
  }
  EXPECT_TRUE(found) << "the point (0.2, 0, 0) of the file is not at position + (0.2, 0, 0)";
}

TEST(RigidScene, BodiesMayCarryTheirOwnMaterial) {
  auto scene = parseScene(
      R"({"bodies": [{"shape": {"type": "sphere", "radius": 1}, "mass": 1, "friction": 0.1,
                      "restitution": 0.9},
                     {"shape": {"type": "sphere", "radius": 1}, "mass": 1}]})",
      "materials.json");
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ((*scene)[0].friction, 0.1);
  EXPECT_EQ((*scene)[0].restitution, 0.9);
  EXPECT_LT((*scene)[1].friction, 0.0);  // none of its own: the interactor's
  EXPECT_LT((*scene)[1].restitution, 0.0);
}

TEST(RigidScene, BadFilesGiveErrorsNamingFileAndLine) {
  const std::string origin = "scenes/bad.json";
  auto syntax = parseScene(
      "{\n  \"bodies\": [\n    {\"shape\": {\"type\": \"sphere\", \"radius\": 1},}\n  ]\n}\n",
      origin);
  ASSERT_FALSE(syntax);
  EXPECT_NE(syntax.error().message.find("scenes/bad.json:3:"), std::string::npos)
      << syntax.error().message;

  auto unknown = parseScene(
      "{\"bodies\": [\n  {\"shape\": {\"type\": \"sphere\", \"radius\": 1}, \"mass\": 1},\n"
      "  {\"name\": \"blob\", \"shape\": {\"type\": \"blob\"}, \"mass\": 1}\n]}\n",
      origin);
  ASSERT_FALSE(unknown);
  EXPECT_NE(
      unknown.error().message.find("scenes/bad.json:3: body 1 'blob': unknown shape type 'blob'"),
      std::string::npos)
      << unknown.error().message;

  for (
      const char* body :
      {R"({"shape": {"type": "sphere", "radius": -1}, "mass": 1})",
       R"({"shape": {"type": "sphere", "radius": 1}})",
       R"({"shape": {"type": "sphere", "radius": 1}, "mass": 1, "density": 2})",
       R"({"shape": {"type": "box", "halfExtents": [1, 1]}, "mass": 1})",
       R"({"shape": {"type": "sphere", "radius": 1}, "mass": 1, "velocity": [1, 0, 0]})",
       R"({"shape": {"type": "sphere", "radius": 1}, "kinematic": true, "mass": 1})",
       R"({"shape": {"type": "convexHull", "points": [[0,0,0],[1,0,0],[0,1,0],[1,1,0]]}, "mass": 1})",
       R"({"shape": {"type": "triangleMesh", "vertices": [[0,0,0],[1,0,0],[0,1,0]], "triangles": [[0,1,3]]}, "kinematic": true})",
       R"({"shape": {"type": "sphere", "radius": 1}, "mass": 1, "orientation": [0, 0, 0, 0]})",
       R"({"shape": {"type": "sphere", "radius": 1}, "mass": 1, "friction": -0.5})",
       R"({"shape": {"type": "sphere", "radius": 1}, "mass": 1, "restitution": 1.5})",
       R"({"shape": {"type": "sphere", "radius": 1}, "mass": 1, "restitution": "high"})"}) {
    auto result = parseScene(std::string("{\"bodies\": [") + body + "]}", origin);
    ASSERT_FALSE(result) << body;
    EXPECT_EQ(result.error().message.rfind("scenes/bad.json:1: body 0: ", 0), 0u)
        << result.error().message;
  }
  auto missing = loadScene("/nonexistent/scene.json");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("/nonexistent/scene.json"), std::string::npos);
}

// A scene is read only from a regular file of at most 256 MiB: a device, a FIFO (without
// blocking) or a folder is refused with one error naming the file and what it is.
TEST(RigidScene, SceneFromADeviceFifoFolderOrHugeFileIsRefusedWithoutReadingIt) {
  auto zero = loadScene("/dev/zero");
  ASSERT_FALSE(zero);
  EXPECT_EQ(zero.error().message,
            "/dev/zero: scene file: cannot read file (it is a character device, not a regular "
            "file)");
  testing::TempDir dir;
  const std::string fifo = dir.file("scene.json");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  // Hang guard: a reader that blocks in open() is released by a writer after 20 s.
  auto fromFifo = std::async(std::launch::async, [&] { return loadScene(fifo); });
  if (fromFifo.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
    const int writer = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (writer >= 0) close(writer);
    ADD_FAILURE() << "loadScene blocked on a FIFO for 20 s";
  }
  const auto fifoResult = fromFifo.get();
  ASSERT_FALSE(fifoResult);
  EXPECT_EQ(fifoResult.error().message,
            fifo + ": scene file: cannot read file (it is a FIFO, not a regular file)");
  auto folder = loadScene(dir.path());
  ASSERT_FALSE(folder);
  EXPECT_NE(folder.error().message.find("it is a directory, not a regular file"), std::string::npos)
      << folder.error().message;
  const std::string huge = dir.file("huge.json");
  std::ofstream(huge) << "{\"bodies\": [";
  std::filesystem::resize_file(huge, std::uintmax_t{1} << 30);  // 1 GiB, sparse
  auto tooLarge = loadScene(huge);
  ASSERT_FALSE(tooLarge);
  EXPECT_EQ(tooLarge.error().message,
            huge +
                ": scene file: cannot read file (it is 1073741824 bytes, above the limit of "
                "268435456 bytes (256 MiB))");
}

TEST(RigidScene, GeneratorsAndTheirErrors) {
  auto boxes = generateScene("boxes:200");
  ASSERT_TRUE(boxes);
  EXPECT_EQ(boxes->size(), 201u);
  EXPECT_TRUE((*boxes)[0].kinematic);
  auto mixed = generateScene("mixed:20");
  ASSERT_TRUE(mixed);
  EXPECT_EQ(mixed->size(), 25u);  // ground, four walls, 20 objects
  int kinds[6] = {};
  for (const auto& b : *mixed)
    if (!b.kinematic) ++kinds[static_cast<int>(b.shape.kind)];
  EXPECT_EQ(kinds[1] + kinds[2] + kinds[3] + kinds[4], 20);
  EXPECT_EQ(kinds[4], 5);
  for (const char* bad : {"boxes", "boxes:0", "boxes:x", "pyramid:3", "boxes:3x"})
    EXPECT_FALSE(generateScene(bad)) << bad;
}

}  // namespace
}  // namespace vrflow::rigid
