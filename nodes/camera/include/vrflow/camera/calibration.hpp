#pragma once
// A calibrated camera: intrinsics, distortion and pose in the simulation's world frame, stored in
// OpenCV's own cv::FileStorage format (YAML or XML by the file's extension). Units: pixels for the
// image, metres for the world. The pose maps the world to the camera: x_cam = R x_world + T.

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::camera {

/// One camera's calibration. Field names in the file are those of OpenCV's calibration sample
/// (image_width, image_height, camera_matrix, distortion_coefficients) plus the world pose
/// (rotation_matrix, translation_vector: world to camera, as cv::solvePnP gives) and an optional
/// reprojection error (avg_reprojection_error, pixels).
struct CameraCalibration {
  cv::Size imageSize;
  cv::Matx33d cameraMatrix = cv::Matx33d::eye();
  cv::Mat distortion = cv::Mat::zeros(1, 5, CV_64F);  ///< k1 k2 p1 p2 [k3 ...], OpenCV's order
  cv::Matx33d rotation = cv::Matx33d::eye();          ///< world to camera
  cv::Vec3d translation{0, 0, 0};                     ///< world to camera (metres)
  double reprojectionError = 0;                       ///< RMS, pixels (0 when unknown)

  /// The camera's centre in the world frame.
  cv::Vec3d centre() const { return -(rotation.t() * translation); }
  /// The pinhole projection matrix K [R | T] (no distortion).
  cv::Matx34d projection() const;
};

/// Reads a calibration written by saveCalibration or OpenCV's tools; one error per missing or
/// malformed field, naming the file (and the line where OpenCV's parser gives it).
Result<CameraCalibration> loadCalibration(const std::string& path);

/// The calibration files a module is given, each with what names it in errors: `names` (file
/// names separated by spaces, as written) or the lines of the file `list` (relative names
/// relative to the list's folder; blank lines and lines starting with '#' skipped). Errors:
/// both or neither given, a list that cannot be read, no file named (file:line in messages).
Result<std::vector<std::pair<std::string, std::string>>> calibrationFiles(const std::string& names,
                                                                          const std::string& list);

/// Writes `calibration` to `path` (.yml/.yaml or .xml), in the format loadCalibration reads.
Status saveCalibration(const CameraCalibration& calibration, const std::string& path);

/// A camera looking from `eye` at `target` with `up` roughly up (world frame), ideal pinhole
/// intrinsics of focal length `focal` pixels centred in `size`: for synthetic rigs.
CameraCalibration lookAtCamera(cv::Size size, double focal, const cv::Vec3d& eye,
                               const cv::Vec3d& target, const cv::Vec3d& up = {0, 1, 0});

}  // namespace vrflow::camera
