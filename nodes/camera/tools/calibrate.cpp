// vrflow-camera-calibrate: one camera's intrinsics, distortion and world pose from images of a
// chessboard, written in OpenCV's FileStorage format (nodes/camera/README.md).
//   vrflow-camera-calibrate --board 9x6 --square 0.03 --views 'cam0/view_*.png'
//       --world cam0/world.png [--board-rotation RX RY RZ] [--board-position X Y Z] --out cam0.yml
#include <CLI/CLI.hpp>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vrflow/camera/chessboard.hpp"

namespace {

using vrflow::camera::ChessboardSpec;

int fail(const std::string& message) {
  std::fprintf(stderr, "vrflow-camera-calibrate: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "One camera's calibration (intrinsics, distortion, world pose) from chessboard images"};
  std::string boardText = "9x6", viewsPattern, worldImage, out;
  double square = 0.03;
  std::vector<double> boardRotation{0, 0, 0}, boardPosition{0, 0, 0};
  app.add_option("--board", boardText, "Inner corners per row x per column")->capture_default_str();
  app.add_option("--square", square, "Square side (m)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--views", viewsPattern, "Images of the board in many poses (a glob, quoted)")
      ->required();
  app.add_option("--world", worldImage,
                 "Image of the board placed where it defines the world frame")
      ->required();
  app.add_option("--board-rotation", boardRotation,
                 "The world board's rotation in the world (Rodrigues vector, rad)")
      ->expected(3);
  app.add_option("--board-position", boardPosition,
                 "The world board's first inner corner in the world (m)")
      ->expected(3);
  app.add_option("--out", out, "Calibration file to write (.yml or .xml)")->required();
  CLI11_PARSE(app, argc, argv);

  ChessboardSpec board;
  board.squareSize = square;
  if (std::sscanf(boardText.c_str(), "%dx%d", &board.innerCorners.width,
                  &board.innerCorners.height) != 2 ||
      board.innerCorners.width < 2 || board.innerCorners.height < 2)
    return fail("--board " + boardText + ": expected COLSxROWS inner corners, e.g. 9x6");
  std::vector<cv::String> files;
  cv::glob(viewsPattern, files, false);
  if (files.empty()) return fail("--views " + viewsPattern + ": no image matches");
  std::vector<cv::Mat> views;
  for (const auto& file : files) {
    cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
    if (image.empty()) return fail(file + ": not a readable image");
    views.push_back(image);
  }
  auto camera = vrflow::camera::calibrateIntrinsics(views, board);
  if (!camera) return fail(viewsPattern + ": " + camera.error().message);
  const cv::Mat world = cv::imread(worldImage, cv::IMREAD_GRAYSCALE);
  if (world.empty()) return fail(worldImage + ": not a readable image");
  cv::Matx33d rotation;
  cv::Rodrigues(cv::Vec3d(boardRotation[0], boardRotation[1], boardRotation[2]), rotation);
  if (auto status = vrflow::camera::setWorldPose(
          *camera, world, board, rotation, {boardPosition[0], boardPosition[1], boardPosition[2]});
      !status)
    return fail(worldImage + ": " + status.error().message);
  if (auto status = vrflow::camera::saveCalibration(*camera, out); !status)
    return fail(status.error().message);
  std::printf("{\"views\": %zu, \"reprojection_error_px\": %.4f, \"out\": \"%s\"}\n", files.size(),
              camera->reprojectionError, out.c_str());
  return 0;
}
