#pragma once
// Calibration from images of a chessboard: corner detection (findChessboardCorners, cornerSubPix),
// intrinsics (calibrateCamera) and the world pose from one view of a board placed in the world.

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/calibration.hpp"

namespace vrflow::camera {

/// A chessboard: inner corners per row and column, square side (metres). Board frame: origin at
/// the first inner corner, x along a row, y down the columns, z into the board (OpenCV's).
struct ChessboardSpec {
  cv::Size innerCorners{9, 6};
  double squareSize = 0.03;

  /// The inner corners in the board frame, in findChessboardCorners' order.
  std::vector<cv::Point3f> objectPoints() const;
};

/// The inner corners of `board` in a grey or colour image, refined to sub-pixel; none if the
/// board is not found whole.
std::optional<std::vector<cv::Point2f>> detectChessboard(const cv::Mat& image,
                                                         const ChessboardSpec& board);

/// Intrinsics and distortion from views of a board (at least 3 where it was found); the pose is
/// left at identity. Errors: too few views, images of different sizes.
Result<CameraCalibration> calibrateIntrinsics(const std::vector<cv::Mat>& views,
                                              const ChessboardSpec& board);

/// Sets `camera`'s world pose from an image of the board whose pose in the world is
/// `boardToWorld` (rotation, translation): x_world = R x_board + t.
Status setWorldPose(CameraCalibration& camera, const cv::Mat& image, const ChessboardSpec& board,
                    const cv::Matx33d& boardRotation, const cv::Vec3d& boardTranslation);

/// Renders `board` (with a white margin of one square) as seen by `camera` from the board pose
/// x_cam = R x_board + t, antialiased by 4x4 supersampling, through the camera's distortion, on
/// a grey background: the synthetic images the calibration tests use.
cv::Mat renderChessboard(const CameraCalibration& camera, const ChessboardSpec& board,
                         const cv::Matx33d& boardToCameraRotation,
                         const cv::Vec3d& boardToCameraTranslation);

}  // namespace vrflow::camera
