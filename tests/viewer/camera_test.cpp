// Fixed and scripted cameras.
#include "vrflow/viewer/camera.hpp"

#include <gtest/gtest.h>

namespace vrflow::viewer {
namespace {

TEST(CameraPath, FixedCameraIsTheSameAtEveryIteration) {
  Camera c;
  c.eye = {1, 2, 3};
  const CameraPath path(c);
  EXPECT_EQ(path.at(0).eye, c.eye);
  EXPECT_EQ(path.at(1000).eye, c.eye);
}

TEST(CameraPath, KeysAreInterpolatedLinearlyAndHeldAtTheEnds) {
  const auto path = CameraPath::parse(
      "# iteration eye target fov\n"
      "10  0 1 10   0 0 0\n"
      "\n"
      "20  10 1 0   0 2 0  60\n",
      Camera{});
  ASSERT_TRUE(path.ok()) << path.error().message;
  ASSERT_EQ(path->keys().size(), 2u);
  EXPECT_EQ(path->at(0).eye, (msg::Vec3{0, 1, 10}));   // before the first key
  EXPECT_EQ(path->at(99).eye, (msg::Vec3{10, 1, 0}));  // after the last
  const Camera half = path->at(15);
  EXPECT_DOUBLE_EQ(half.eye[0], 5.0);
  EXPECT_DOUBLE_EQ(half.eye[2], 5.0);
  EXPECT_DOUBLE_EQ(half.target[1], 1.0);
  EXPECT_DOUBLE_EQ(half.fovYDegrees, (Camera{}.fovYDegrees + 60.0) / 2);
}

TEST(CameraPath, BadTextIsRefusedWithItsLine) {
  const auto missing = CameraPath::parse("0 1 2 3 4 5\n", Camera{});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("line 1"), std::string::npos);
  const auto order = CameraPath::parse("5 0 0 1 0 0 0\n5 0 0 2 0 0 0\n", Camera{});
  ASSERT_FALSE(order.ok());
  EXPECT_NE(order.error().message.find("does not follow"), std::string::npos);
  const auto extra = CameraPath::parse("0 0 0 1 0 0 0 45 junk\n", Camera{});
  ASSERT_FALSE(extra.ok());
  const auto same = CameraPath::parse("0 1 1 1 1 1 1\n", Camera{});
  ASSERT_FALSE(same.ok());
  EXPECT_FALSE(CameraPath::parse("# nothing\n", Camera{}).ok());
  EXPECT_FALSE(CameraPath::load("/nonexistent/path.txt", Camera{}).ok());
}

}  // namespace
}  // namespace vrflow::viewer
