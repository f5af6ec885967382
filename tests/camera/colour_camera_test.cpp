// The synthetic colour camera and the capture sources: the rendered user lies where the exact
// silhouette says, through any calibration; image sequences end with an error.
#include "vrflow/camera/colour_camera.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "process_helpers.hpp"
#include "vrflow/camera/capture_source.hpp"
#include "vrflow/camera/synthetic_scene.hpp"

namespace vrflow::camera {
namespace {

using vrflow::testing::TempDir;

// Pixels where `image` differs from the empty room: the drawn user.
cv::Mat drawnMask(const cv::Mat& image, const cv::Mat& room) {
  cv::Mat difference;
  cv::absdiff(image, room, difference);
  cv::Mat grey;
  cv::transform(difference, grey, cv::Matx13f(1, 1, 1));
  return grey > 0;
}

double maskIoU(const cv::Mat& a, const cv::Mat& b) {
  const double both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either > 0 ? both / either : 1.0;
}

TEST(ColourCamera, EmptyRoomIsTheRoomTextureAndTheUserCoversItsExactSilhouette) {
  const auto calibration = cameraRing(5)[1];
  auto camera = ColourCamera::create(calibration, {3, 0.0, 48});
  ASSERT_TRUE(camera.ok()) << camera.error().message;
  const cv::Mat room = renderBackground(calibration.imageSize, 3, 0, 0);
  auto empty = camera->render(nullptr, 0);
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(cv::norm(*empty, room, cv::NORM_INF), 0);
  const SyntheticUser user(standingPose());
  auto image = camera->render(&user, 0);
  ASSERT_TRUE(image.ok()) << image.error().message;
  const double iou = maskIoU(drawnMask(*image, room), user.renderMask(calibration));
  std::printf("rendered user against its exact silhouette: IoU %.4f\n", iou);
  EXPECT_GE(iou, 0.97);
}

TEST(ColourCamera, OffCentrePrincipalPointAndLensDistortionAreRenderedAsCalibrated) {
  auto calibration = cameraRing(5)[0];
  calibration.cameraMatrix(0, 2) += 40;  // principal point off centre
  calibration.cameraMatrix(1, 2) -= 25;
  calibration.cameraMatrix(1, 1) *= 1.05;  // non-square pixels
  calibration.distortion = (cv::Mat_<double>(1, 5) << -0.2, 0.05, 0.001, -0.001, 0);
  auto camera = ColourCamera::create(calibration, {0, 0.0, 48});
  ASSERT_TRUE(camera.ok());
  const SyntheticUser user(standingPose());
  auto image = camera->render(&user, 0);
  ASSERT_TRUE(image.ok());
  const cv::Mat room = renderBackground(calibration.imageSize, 0, 0, 0);
  const double iou = maskIoU(drawnMask(*image, room), user.renderMask(calibration));
  std::printf("distorted, off-centre render against the exact silhouette: IoU %.4f\n", iou);
  EXPECT_GE(iou, 0.95);
}

TEST(ColourCamera, TheSameFrameGivesTheSameBitsAndNoiseChangesWithTheFrame) {
  const auto calibration = cameraRing(5)[2];
  auto a = ColourCamera::create(calibration, {2, 2.0, 48});
  auto b = ColourCamera::create(calibration, {2, 2.0, 48});
  ASSERT_TRUE(a.ok() && b.ok());
  const SyntheticUser user(standingPose());
  const cv::Mat first = *a->render(&user, 7);
  EXPECT_EQ(cv::norm(first, *b->render(&user, 7), cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(first, *a->render(&user, 8), cv::NORM_INF), 0);
}

CaptureSettings sequenceSettings(const std::string& source, cv::Size size) {
  CaptureSettings settings;
  settings.source = source;
  settings.calibration = cameraRing(1, size)[0];
  return settings;
}

TEST(CaptureSource, ImageSequencesDeliverTheirFramesThenStopWithAnError) {
  TempDir dir;
  std::vector<cv::Mat> written;
  for (int n = 0; n < 3; ++n) {
    written.push_back(renderBackground({64, 48}, n, 0, 0));
    ASSERT_TRUE(cv::imwrite(dir.file("f_" + std::to_string(n) + ".png"), written.back()));
  }
  for (const std::string pattern : {"f_%d.png", "f_*.png"}) {
    auto source = openCaptureSource(sequenceSettings(dir.file(pattern), {64, 48}));
    ASSERT_TRUE(source.ok()) << source.error().message;
    for (int n = 0; n < 3; ++n) {
      auto frame = (*source)->next();
      ASSERT_TRUE(frame.ok()) << frame.error().message;
      EXPECT_EQ(cv::norm(frame->image, written[static_cast<std::size_t>(n)], cv::NORM_INF), 0);
    }
    auto end = (*source)->next();
    ASSERT_FALSE(end.ok());
    EXPECT_NE(end.error().message.find("stopped delivering: no frame 3"), std::string::npos)
        << end.error().message;
  }
  auto wrong = openCaptureSource(sequenceSettings(dir.file("f_*.png"), {640, 480}));
  ASSERT_TRUE(wrong.ok());
  auto frame = (*wrong)->next();
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.error().message, "frame 0 is 64x48, the calibration says 640x480");
}

TEST(CaptureSource, AVideoFileDeliversItsFramesThenStopsWithAnError) {
  TempDir dir;
  const auto path = dir.file("clip.avi");
  {
    // OpenCV's own Motion-JPEG writer: no codec library needed.
    cv::VideoWriter writer(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                           10, {64, 48});
    ASSERT_TRUE(writer.isOpened());
    for (int n = 0; n < 4; ++n) writer.write(renderBackground({64, 48}, n, 0, 0));
  }
  auto source = openCaptureSource(sequenceSettings(path, {64, 48}));
  ASSERT_TRUE(source.ok()) << source.error().message;
  for (int n = 0; n < 4; ++n) {
    auto frame = (*source)->next();
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    // JPEG is lossy: the frame is near the image written, and nearer it than to the others.
    const cv::Mat written = renderBackground({64, 48}, n, 0, 0);
    const cv::Mat other = renderBackground({64, 48}, n + 1, 0, 0);
    EXPECT_LT(cv::norm(frame->image, written, cv::NORM_L1),
              0.5 * cv::norm(frame->image, other, cv::NORM_L1));
  }
  auto end = (*source)->next();
  ASSERT_FALSE(end.ok());
  EXPECT_EQ(end.error().message.rfind("stopped delivering: no frame 4 (it gave 4 frames", 0), 0u)
      << end.error().message;
}

TEST(CaptureSource, UnknownSourcesAreRefusedNamingTheForms) {
  for (const std::string source : {"", "synthetik", "/no/such/video.avi", "/dev/video"}) {
    auto opened = openCaptureSource(sequenceSettings(source, {64, 48}));
    ASSERT_FALSE(opened.ok()) << source;
    EXPECT_NE(opened.error().message.find("source '" + source + "': not a regular file"),
              std::string::npos)
        << opened.error().message;
  }
}

}  // namespace
}  // namespace vrflow::camera
