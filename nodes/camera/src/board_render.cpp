// renderChessboard: the synthetic views of a board for the calibration tests and tools.
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "vrflow/camera/chessboard.hpp"

namespace vrflow::camera {

namespace {

constexpr int kSamples = 4;  // per pixel side

}  // namespace

cv::Mat renderChessboard(const CameraCalibration& camera, const ChessboardSpec& board,
                         const cv::Matx33d& boardToCameraRotation,
                         const cv::Vec3d& boardToCameraTranslation) {
  const cv::Size size = camera.imageSize;
  // Every sample's normalised ray (through the distortion, undone by undistortPoints).
  std::vector<cv::Point2f> samples;
  samples.reserve(static_cast<std::size_t>(size.area()) * kSamples * kSamples);
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u)
      for (int sv = 0; sv < kSamples; ++sv)
        for (int su = 0; su < kSamples; ++su)
          samples.emplace_back(static_cast<float>(u - 0.5 + (su + 0.5) / kSamples),
                               static_cast<float>(v - 0.5 + (sv + 0.5) / kSamples));
  std::vector<cv::Point2f> rays;
  cv::undistortPoints(samples, rays, camera.cameraMatrix, camera.distortion);
  // The ray x = o + s d in the board frame meets the plane z = 0.
  const cv::Matx33d toBoard = boardToCameraRotation.t();
  const cv::Vec3d origin = -(toBoard * boardToCameraTranslation);
  const double s = board.squareSize;
  const double minX = -2 * s, maxX = (board.innerCorners.width + 1) * s;
  const double minY = -2 * s, maxY = (board.innerCorners.height + 1) * s;
  cv::Mat image(size, CV_8UC1);
  std::size_t i = 0;
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      double sum = 0;
      for (int k = 0; k < kSamples * kSamples; ++k, ++i) {
        const cv::Vec3d d = toBoard * cv::Vec3d(rays[i].x, rays[i].y, 1.0);
        double shade = 128;  // background
        if (std::abs(d[2]) > 1e-12) {
          const double along = -origin[2] / d[2];
          const double x = origin[0] + along * d[0], y = origin[1] + along * d[1];
          if (along > 0 && x >= minX && x <= maxX && y >= minY && y <= maxY) {
            shade = 255;  // margin
            const bool inSquares = x >= -s && x <= board.innerCorners.width * s && y >= -s &&
                                   y <= board.innerCorners.height * s;
            const auto cx = static_cast<long>(std::floor(x / s));
            const auto cy = static_cast<long>(std::floor(y / s));
            if (inSquares && ((cx + cy) % 2 == 0)) shade = 0;
          }
        }
        sum += shade;
      }
      image.at<std::uint8_t>(v, u) =
          static_cast<std::uint8_t>(std::lround(sum / (kSamples * kSamples)));
    }
  }
  return image;
}

}  // namespace vrflow::camera
