#include "vrflow/camera/chessboard.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace vrflow::camera {

namespace {

cv::Mat toGrey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

}  // namespace

std::vector<cv::Point3f> ChessboardSpec::objectPoints() const {
  std::vector<cv::Point3f> points;
  for (int row = 0; row < innerCorners.height; ++row)
    for (int col = 0; col < innerCorners.width; ++col)
      points.emplace_back(static_cast<float>(col * squareSize),
                          static_cast<float>(row * squareSize), 0.0f);
  return points;
}

std::optional<std::vector<cv::Point2f>> detectChessboard(const cv::Mat& image,
                                                         const ChessboardSpec& board) {
  const cv::Mat grey = toGrey(image);
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(grey, board.innerCorners, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
    return std::nullopt;
  cv::cornerSubPix(grey, corners, {11, 11}, {-1, -1},
                   {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4});
  return corners;
}

Result<CameraCalibration> calibrateIntrinsics(const std::vector<cv::Mat>& views,
                                              const ChessboardSpec& board) {
  if (views.empty()) return makeError("no calibration image");
  std::vector<std::vector<cv::Point2f>> imagePoints;
  const cv::Size size = views.front().size();
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].size() != size)
      return makeError("calibration image " + std::to_string(i) + " is " +
                       std::to_string(views[i].cols) + "x" + std::to_string(views[i].rows) +
                       ", the first is " + std::to_string(size.width) + "x" +
                       std::to_string(size.height) + ": all views of a camera share its size");
    if (auto corners = detectChessboard(views[i], board)) imagePoints.push_back(*corners);
  }
  if (imagePoints.size() < 3)
    return makeError("the " + std::to_string(board.innerCorners.width) + "x" +
                     std::to_string(board.innerCorners.height) + " board was found in " +
                     std::to_string(imagePoints.size()) + " of " + std::to_string(views.size()) +
                     " images; calibration needs at least 3");
  const std::vector<std::vector<cv::Point3f>> objectPoints(imagePoints.size(),
                                                           board.objectPoints());
  CameraCalibration camera;
  camera.imageSize = size;
  cv::Mat k, dist, rvecs, tvecs;
  camera.reprojectionError =
      cv::calibrateCamera(objectPoints, imagePoints, size, k, dist, rvecs, tvecs);
  camera.cameraMatrix = cv::Matx33d(k.ptr<double>());
  camera.distortion = dist.reshape(1, 1);
  return camera;
}

Status setWorldPose(CameraCalibration& camera, const cv::Mat& image, const ChessboardSpec& board,
                    const cv::Matx33d& boardRotation, const cv::Vec3d& boardTranslation) {
  if (image.size() != camera.imageSize)
    return makeError("the world-board image is " + std::to_string(image.cols) + "x" +
                     std::to_string(image.rows) + ", the camera's " +
                     std::to_string(camera.imageSize.width) + "x" +
                     std::to_string(camera.imageSize.height));
  const auto corners = detectChessboard(image, board);
  if (!corners) return makeError("the world board is not found whole in its image");
  cv::Vec3d rvec, tvec;
  if (!cv::solvePnP(board.objectPoints(), *corners, camera.cameraMatrix, camera.distortion, rvec,
                    tvec, false, cv::SOLVEPNP_ITERATIVE))
    return makeError("the world board's pose could not be solved");
  cv::Matx33d boardToCamera;
  cv::Rodrigues(rvec, boardToCamera);
  // x_cam = Rb x_board + tb and x_board = Rw^T (x_world - tw).
  camera.rotation = boardToCamera * boardRotation.t();
  camera.translation = tvec - camera.rotation * boardTranslation;
  return {};
}

}  // namespace vrflow::camera
