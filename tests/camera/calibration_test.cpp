// Calibration files: OpenCV's FileStorage format, one clear error per missing or malformed field.
#include "vrflow/camera/calibration.hpp"

#include <gtest/gtest.h>

#include "process_helpers.hpp"

namespace vrflow::camera {
namespace {

using vrflow::testing::TempDir;

constexpr const char* kValidYaml = R"(%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 550., 0., 319.5, 0., 550., 239.5, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.1, 0.01, 0., 0., 0. ]
rotation_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]
translation_vector: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 0.1, -0.2, 2.5 ]
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(CalibrationFile, ReadsOpenCvYamlAsItsToolsWriteIt) {
  TempDir dir;
  auto camera = loadCalibration(dir.write("cam.yml", kValidYaml));
  ASSERT_TRUE(camera) << camera.error().message;
  EXPECT_EQ(camera->imageSize, cv::Size(640, 480));
  EXPECT_DOUBLE_EQ(camera->cameraMatrix(0, 2), 319.5);
  EXPECT_DOUBLE_EQ(camera->distortion.at<double>(0, 0), -0.1);
  EXPECT_DOUBLE_EQ(camera->translation[2], 2.5);
  EXPECT_NEAR(camera->centre()[1], 0.2, 1e-12);
}

TEST(CalibrationFile, RoundTripsThroughYamlAndXml) {
  TempDir dir;
  CameraCalibration camera = lookAtCamera({800, 600}, 700, {1, 2, 3}, {0, 1, 0});
  camera.distortion = (cv::Mat_<double>(1, 5) << 0.05, -0.01, 0.001, 0.002, 0.0);
  camera.reprojectionError = 0.12;
  for (const char* name : {"cam.yml", "cam.xml"}) {
    ASSERT_TRUE(saveCalibration(camera, dir.file(name)));
    auto back = loadCalibration(dir.file(name));
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->imageSize, camera.imageSize);
    EXPECT_LT(cv::norm(back->cameraMatrix - camera.cameraMatrix), 1e-12);
    EXPECT_LT(cv::norm(back->rotation - camera.rotation), 1e-12);
    EXPECT_LT(cv::norm(back->translation - camera.translation), 1e-12);
    EXPECT_LT(cv::norm(back->distortion - camera.distortion), 1e-12);
    EXPECT_DOUBLE_EQ(back->reprojectionError, 0.12);
  }
}

TEST(CalibrationFile, AMissingFileIsOneClearError) {
  auto camera = loadCalibration("/nonexistent/cam0.yml");
  ASSERT_FALSE(camera);
  EXPECT_EQ(camera.error().message, "/nonexistent/cam0.yml: no such calibration file");
}

TEST(CalibrationFile, MalformedYamlNamesTheFileAndLine) {
  TempDir dir;
  const std::string path =
      dir.write("cam.yml", replaced(kValidYaml, "data: [ 550., 0.,", "data: [ 550., 0.,, ]]"));
  auto camera = loadCalibration(path);
  ASSERT_FALSE(camera);
  EXPECT_NE(camera.error().message.find(path + ": malformed"), std::string::npos)
      << camera.error().message;
  // OpenCV names the line in parentheses after the file: the matrix's data is on line 9.
  EXPECT_NE(camera.error().message.find(path + "(9)"), std::string::npos) << camera.error().message;
}

TEST(CalibrationFile, AMissingFieldIsNamed) {
  TempDir dir;
  const std::string text = kValidYaml;
  const auto start = text.find("rotation_matrix");
  const auto end = text.find("translation_vector");
  const std::string path = dir.write("cam.yml", text.substr(0, start) + text.substr(end));
  auto camera = loadCalibration(path);
  ASSERT_FALSE(camera);
  EXPECT_EQ(camera.error().message,
            path + ": field 'rotation_matrix' (3x3 world-to-camera rotation) is missing");
}

TEST(CalibrationFile, AMatrixOfTheWrongShapeIsNamed) {
  TempDir dir;
  const std::string path = dir.write(
      "cam.yml", replaced(replaced(kValidYaml, "rows: 3\n   cols: 1", "rows: 2\n   cols: 1"),
                          "data: [ 0.1, -0.2, 2.5 ]", "data: [ 0.1, -0.2 ]"));
  auto camera = loadCalibration(path);
  ASSERT_FALSE(camera);
  EXPECT_EQ(
      camera.error().message,
      path + ": field 'translation_vector' (world-to-camera translation, m) has 2x1 elements");
}

TEST(CalibrationFile, ARotationThatIsNotOneIsRefused) {
  TempDir dir;
  const std::string path =
      dir.write("cam.yml", replaced(kValidYaml, "data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]",
                                    "data: [ 2., 0., 0., 0., 1., 0., 0., 0., 1. ]"));
  auto camera = loadCalibration(path);
  ASSERT_FALSE(camera);
  EXPECT_EQ(camera.error().message,
            path + ": field 'rotation_matrix' is not a rotation (orthonormal, det +1)");
}

TEST(CalibrationFile, ANonNumericImageSizeIsRefused) {
  TempDir dir;
  const std::string path =
      dir.write("cam.yml", replaced(kValidYaml, "image_width: 640", "image_width: wide"));
  auto camera = loadCalibration(path);
  ASSERT_FALSE(camera);
  EXPECT_EQ(camera.error().message,
            path + ": field 'image_width' is not a positive integer (pixels)");
}

}  // namespace
}  // namespace vrflow::camera
