// Calibration from synthetic renders of a chessboard seen from known poses.
#include "vrflow/camera/chessboard.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "process_helpers.hpp"

namespace vrflow::camera {
namespace {

using vrflow::testing::TempDir;

ChessboardSpec board() {
  return {{9, 6}, 0.04};
}

// The true camera: not quite square pixels, an off-centre principal point and barrel distortion.
CameraCalibration trueCamera() {
  CameraCalibration camera;
  camera.imageSize = {640, 480};
  camera.cameraMatrix = {610, 0, 322.5, 0, 600, 236.0, 0, 0, 1};
  camera.distortion = (cv::Mat_<double>(1, 5) << -0.08, 0.02, 0.0, 0.0, 0.0);
  return camera;
}

struct Pose {
  cv::Matx33d rotation;
  cv::Vec3d translation;
};

// Board-to-camera poses: the board's centre 0.75-0.95 m ahead, tilted up to ~35 degrees.
std::vector<Pose> calibrationPoses() {
  std::vector<Pose> poses;
  const ChessboardSpec spec = board();
  const cv::Vec3d centre(4 * spec.squareSize, 2.5 * spec.squareSize, 0);
  for (int n = 0; n < 14; ++n) {
    const double a = 0.55 * std::sin(1.3 * n), b = 0.5 * std::cos(0.9 * n),
                 c = 0.3 * std::sin(0.7 * n);
    cv::Matx33d r;
    cv::Rodrigues(cv::Vec3d(a, b, c), r);
    const cv::Vec3d at(0.08 * std::sin(2.1 * n), 0.06 * std::cos(1.7 * n),
                       0.75 + 0.2 * ((n % 3) / 2.0));
    poses.push_back({r, at - r * centre});
  }
  return poses;
}

// The world board lies on the floor (y = 0): its rows along world x, its columns along world z.
const cv::Matx33d kWorldBoardRotation(1, 0, 0, 0, 0, -1, 0, 1, 0);
const cv::Vec3d kWorldBoardPosition(-0.16, 0.0, -0.1);

// The true camera posed in the world, looking down at the floor board.
CameraCalibration truePosedCamera() {
  CameraCalibration camera = trueCamera();
  const CameraCalibration posed =
      lookAtCamera(camera.imageSize, 600, {0.25, 0.75, 0.55}, {0, 0, 0});
  camera.rotation = posed.rotation;
  camera.translation = posed.translation;
  return camera;
}

cv::Mat worldBoardImage(const CameraCalibration& camera) {
  return renderChessboard(camera, board(), camera.rotation * kWorldBoardRotation,
                          camera.rotation * kWorldBoardPosition + camera.translation);
}

double rotationErrorDegrees(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d rvec;
  cv::Rodrigues(a.t() * b, rvec);
  return cv::norm(rvec) * 180.0 / CV_PI;
}

void expectAccurate(const CameraCalibration& found, const CameraCalibration& truth) {
  EXPECT_LT(found.reprojectionError, 0.5);
  EXPECT_LT(cv::norm(found.cameraMatrix - truth.cameraMatrix), 1.0) << cv::Mat(found.cameraMatrix);
  EXPECT_LT(rotationErrorDegrees(found.rotation, truth.rotation), 0.1);
  EXPECT_LT(cv::norm(found.translation - truth.translation), 1e-3);
  EXPECT_LT(cv::norm(found.centre() - truth.centre()), 1e-3);
}

TEST(Chessboard, RenderedBoardIsFoundWhereItWasProjected) {
  const CameraCalibration camera = trueCamera();
  const Pose pose = calibrationPoses()[3];
  const auto corners =
      detectChessboard(renderChessboard(camera, board(), pose.rotation, pose.translation), board());
  ASSERT_TRUE(corners);
  cv::Vec3d rvec;
  cv::Rodrigues(pose.rotation, rvec);
  std::vector<cv::Point2f> expected;
  cv::projectPoints(board().objectPoints(), rvec, pose.translation, camera.cameraMatrix,
                    camera.distortion, expected);
  double worst = 0;
  for (std::size_t i = 0; i < expected.size(); ++i)
    worst = std::max(worst, cv::norm((*corners)[i] - expected[i]));
  EXPECT_LT(worst, 0.1);
}

TEST(Chessboard, CalibrationRecoversIntrinsicsAndWorldPoseFromSyntheticViews) {
  const CameraCalibration truth = truePosedCamera();
  std::vector<cv::Mat> views;
  for (const Pose& pose : calibrationPoses())
    views.push_back(renderChessboard(truth, board(), pose.rotation, pose.translation));
  auto found = calibrateIntrinsics(views, board());
  ASSERT_TRUE(found) << found.error().message;
  ASSERT_TRUE(setWorldPose(*found, worldBoardImage(truth), board(), kWorldBoardRotation,
                           kWorldBoardPosition));
  expectAccurate(*found, truth);
  RecordProperty("reprojection_error_px", std::to_string(found->reprojectionError));
}

TEST(Chessboard, TooFewViewsWithTheBoardIsAnError) {
  const CameraCalibration truth = trueCamera();
  const Pose pose = calibrationPoses()[0];
  const cv::Mat blank(truth.imageSize, CV_8UC1, cv::Scalar(128));
  auto found = calibrateIntrinsics(
      {renderChessboard(truth, board(), pose.rotation, pose.translation), blank, blank}, board());
  ASSERT_FALSE(found);
  EXPECT_EQ(found.error().message,
            "the 9x6 board was found in 1 of 3 images; calibration needs at least 3");
}

TEST(Chessboard, ViewsOfDifferentSizesAreAnError) {
  auto found =
      calibrateIntrinsics({cv::Mat(480, 640, CV_8UC1), cv::Mat(240, 320, CV_8UC1)}, board());
  ASSERT_FALSE(found);
  EXPECT_EQ(found.error().message,
            "calibration image 1 is 320x240, the first is 640x480: all views of a camera share "
            "its size");
}

// The calibration views as PNG files view_N.png in `dir`.
void writeCalibrationViews(const TempDir& dir, const CameraCalibration& truth) {
  int n = 0;
  for (const Pose& pose : calibrationPoses())
    ASSERT_TRUE(cv::imwrite(dir.file("view_" + std::to_string(n++) + ".png"),
                            renderChessboard(truth, board(), pose.rotation, pose.translation)));
}

TEST(CalibrateTool, WritesACalibrationFileFromImageFiles) {
  TempDir dir;
  const CameraCalibration truth = truePosedCamera();
  writeCalibrationViews(dir, truth);
  ASSERT_TRUE(cv::imwrite(dir.file("world.png"), worldBoardImage(truth)));
  cv::Vec3d boardRotation;
  cv::Rodrigues(kWorldBoardRotation, boardRotation);
  auto number = [](double v) { return std::to_string(v); };
  const auto result = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-camera-calibrate", "--board", "9x6", "--square", "0.04",
       "--views", dir.file("view_*.png"), "--world", dir.file("world.png"), "--board-rotation",
       number(boardRotation[0]), number(boardRotation[1]), number(boardRotation[2]),
       "--board-position", number(kWorldBoardPosition[0]), number(kWorldBoardPosition[1]),
       number(kWorldBoardPosition[2]), "--out", dir.file("cam.yml")},
      120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.out.find("\"views\": 14"), std::string::npos) << result.out;
  auto found = loadCalibration(dir.file("cam.yml"));
  ASSERT_TRUE(found) << found.error().message;
  expectAccurate(*found, truth);
}

TEST(CalibrateTool, AWorldImageOfTheWrongSizeIsOneClearError) {
  TempDir dir;
  const CameraCalibration truth = truePosedCamera();
  writeCalibrationViews(dir, truth);
  ASSERT_TRUE(cv::imwrite(dir.file("world.png"), cv::Mat(240, 320, CV_8UC1, cv::Scalar(90))));
  const auto result = vrflow::testing::runCommand(
      {vrflow::testing::binDir() + "/vrflow-camera-calibrate", "--board", "9x6", "--square", "0.04",
       "--views", dir.file("view_*.png"), "--world", dir.file("world.png"), "--out",
       dir.file("cam.yml")},
      120);
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_EQ(result.err, "vrflow-camera-calibrate: " + dir.file("world.png") +
                            ": the world-board image is 320x240, the camera's 640x480\n");
  EXPECT_FALSE(std::ifstream(dir.file("cam.yml")).good());
}

}  // namespace
}  // namespace vrflow::camera
