#include "vrflow/camera/calibration.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace vrflow::camera {

namespace {

// A matrix field: present, a matrix of `rows` x `cols` (cols 0: any) of finite numbers.
Result<cv::Mat> readMatrix(const cv::FileStorage& fs, const std::string& path, const char* name,
                           int rows, int cols, const char* what) {
  const cv::FileNode node = fs[name];
  const std::string where = path + ": field '" + name + "' (" + what + ")";
  if (node.empty()) return makeError(where + " is missing");
  cv::Mat value;
  try {
    node >> value;
  } catch (const cv::Exception& e) {
    return makeError(where + " is not a matrix: " + e.msg);
  }
  if (value.empty()) return makeError(where + " is not an opencv-matrix");
  if (value.rows * value.cols != rows * std::max(cols, 1) && cols != 0)
    return makeError(where + " has " + std::to_string(value.rows) + "x" +
                     std::to_string(value.cols) + " elements");
  value.convertTo(value, CV_64F);
  if (cols == 0) {
    if (value.total() < 4 || value.total() > 14)
      return makeError(where + " has " + std::to_string(value.total()) +
                       " elements (OpenCV takes 4, 5, 8, 12 or 14)");
    value = value.reshape(1, 1);
  } else {
    value = value.reshape(1, rows);
  }
  if (!cv::checkRange(value)) return makeError(where + " holds a NaN or infinite value");
  return value;
}

Result<int> readSize(const cv::FileStorage& fs, const std::string& path, const char* name) {
  const cv::FileNode node = fs[name];
  const std::string where = path + ": field '" + name + "'";
  if (node.empty()) return makeError(where + " (pixels) is missing");
  if (!node.isInt() || static_cast<int>(node) <= 0)
    return makeError(where + " is not a positive integer (pixels)");
  return static_cast<int>(node);
}

}  // namespace

cv::Matx34d CameraCalibration::projection() const {
  cv::Matx34d rt;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rt(r, c) = rotation(r, c);
    rt(r, 3) = translation[r];
  }
  return cameraMatrix * rt;
}

Result<CameraCalibration> loadCalibration(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    return makeError(path + ": no such calibration file");
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ))
      return makeError(path + ": not a cv::FileStorage file (YAML or XML)");
  } catch (const cv::Exception& e) {
    // OpenCV's parser names the line: "... (line N) ..." in e.msg.
    return makeError(path + ": malformed: " + e.msg);
  }
  CameraCalibration camera;
  auto width = readSize(fs, path, "image_width");
  if (!width) return width.error();
  auto height = readSize(fs, path, "image_height");
  if (!height) return height.error();
  camera.imageSize = {*width, *height};
  auto k = readMatrix(fs, path, "camera_matrix", 3, 3, "3x3 intrinsics");
  if (!k) return k.error();
  camera.cameraMatrix = cv::Matx33d(k->ptr<double>());
  if (camera.cameraMatrix(0, 0) <= 0 || camera.cameraMatrix(1, 1) <= 0)
    return makeError(path + ": field 'camera_matrix' has a non-positive focal length");
  auto dist = readMatrix(fs, path, "distortion_coefficients", 1, 0, "k1 k2 p1 p2 [k3...]");
  if (!dist) return dist.error();
  camera.distortion = *dist;
  auto r = readMatrix(fs, path, "rotation_matrix", 3, 3, "3x3 world-to-camera rotation");
  if (!r) return r.error();
  camera.rotation = cv::Matx33d(r->ptr<double>());
  const cv::Matx33d shouldBeIdentity = camera.rotation.t() * camera.rotation;
  if (cv::norm(shouldBeIdentity - cv::Matx33d::eye()) > 1e-6 ||
      cv::determinant(camera.rotation) < 0)
    return makeError(path + ": field 'rotation_matrix' is not a rotation (orthonormal, det +1)");
  auto t = readMatrix(fs, path, "translation_vector", 3, 1, "world-to-camera translation, m");
  if (!t) return t.error();
  camera.translation = cv::Vec3d(t->ptr<double>());
  const cv::FileNode error = fs["avg_reprojection_error"];
  if (!error.empty()) {
    if (!error.isReal() && !error.isInt())
      return makeError(path + ": field 'avg_reprojection_error' is not a number (pixels)");
    camera.reprojectionError = static_cast<double>(error);
  }
  return camera;
}

Status saveCalibration(const CameraCalibration& camera, const std::string& path) {
  try {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    if (!fs.isOpened()) return makeError(path + ": cannot be written");
    fs << "image_width" << camera.imageSize.width << "image_height" << camera.imageSize.height;
    fs << "camera_matrix" << cv::Mat(camera.cameraMatrix);
    fs << "distortion_coefficients" << camera.distortion;
    fs << "rotation_matrix" << cv::Mat(camera.rotation);
    fs << "translation_vector" << cv::Mat(camera.translation);
    fs << "avg_reprojection_error" << camera.reprojectionError;
  } catch (const cv::Exception& e) {
    return makeError(path + ": cannot be written: " + e.msg);
  }
  return {};
}

CameraCalibration lookAtCamera(cv::Size size, double focal, const cv::Vec3d& eye,
                               const cv::Vec3d& target, const cv::Vec3d& up) {
  CameraCalibration camera;
  camera.imageSize = size;
  camera.cameraMatrix = {focal, 0, (size.width - 1) / 2.0, 0, focal, (size.height - 1) / 2.0, 0,
                         0,     1};
  // Camera axes in the world: z forward, x right, y down (OpenCV's).
  const cv::Vec3d z = cv::normalize(target - eye);
  const cv::Vec3d x = cv::normalize(z.cross(up));
  const cv::Vec3d y = z.cross(x);
  camera.rotation = {x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]};
  camera.translation = -(camera.rotation * eye);
  return camera;
}

Result<std::vector<std::pair<std::string, std::string>>> calibrationFiles(const std::string& names,
                                                                          const std::string& list) {
  std::vector<std::pair<std::string, std::string>> files;
  std::istringstream words(names);
  for (std::string file; words >> file;) files.emplace_back(file, "parameter 'calibrations'");
  if (!files.empty() && !list.empty()) {
    return makeError("give parameter 'calibrations' or 'calibration-list', not both");
  }
  if (list.empty()) {
    if (files.empty()) {
      return makeError(
          "parameter 'calibrations': no calibration file given (or give 'calibration-list')");
    }
    return files;
  }
  std::ifstream in(list);
  if (!in) return makeError("parameter 'calibration-list': cannot read " + list);
  const std::filesystem::path folder = std::filesystem::path(list).parent_path();
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos || line[begin] == '#') continue;
    const auto end = line.find_last_not_of(" \t\r");
    const std::filesystem::path file(line.substr(begin, end - begin + 1));
    files.emplace_back((file.is_relative() ? folder / file : file).lexically_normal().string(),
                       "parameter 'calibration-list': " + list + ":" + std::to_string(number));
  }
  if (files.empty()) {
    return makeError("parameter 'calibration-list': " + list + " names no calibration file");
  }
  return files;
}

}  // namespace vrflow::camera
