// Silhouettes from synthetic images: a textured room, the rendered user, sensor noise.
#include "vrflow/camera/silhouette.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "vrflow/camera/synthetic_scene.hpp"

namespace vrflow::camera {
namespace {

double maskIoU(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat both, either;
  cv::bitwise_and(a, b, both);
  cv::bitwise_or(a, b, either);
  return static_cast<double>(cv::countNonZero(both)) / cv::countNonZero(either);
}

// Learns the background from 10 noisy frames, then extracts the user from a noisy frame.
double extractedIoU(const SilhouetteSettings& settings, int cameraIndex,
                    std::vector<std::vector<cv::Point>>* contours = nullptr) {
  const CameraCalibration camera = cameraRing(5)[static_cast<std::size_t>(cameraIndex)];
  const SyntheticUser user(standingPose());
  SilhouetteExtractor extractor(camera.imageSize, settings);
  for (std::uint64_t n = 0; n < 10; ++n)
    EXPECT_TRUE(
        extractor.learnBackground(renderBackground(camera.imageSize, cameraIndex, 6.0, n + 1)));
  auto mask = extractor.extract(renderUserImage(user, camera, cameraIndex, 6.0, 99), contours);
  EXPECT_TRUE(mask) << mask.error().message;
  return mask ? maskIoU(*mask, user.renderMask(camera)) : 0.0;
}

TEST(Silhouette, StaticBackgroundGivesTheUsersMask) {
  for (int camera = 0; camera < 5; ++camera) {
    const double iou = extractedIoU({}, camera);
    EXPECT_GT(iou, 0.97) << "camera " << camera;
  }
}

TEST(Silhouette, Mog2BackgroundGivesTheUsersMask) {
  SilhouetteSettings settings;
  settings.model = SilhouetteSettings::Model::kMog2;
  EXPECT_GT(extractedIoU(settings, 2), 0.95);
}

TEST(Silhouette, NoiseSpecklesAreNotKeptAndContoursOutlineTheUser) {
  SilhouetteSettings settings;
  settings.threshold = 12;  // low enough for the noise to cross it here and there
  settings.morphologyRadius = 0;
  std::vector<std::vector<cv::Point>> contours;
  EXPECT_GT(extractedIoU(settings, 0, &contours), 0.95);
  ASSERT_FALSE(contours.empty());
  EXPECT_LE(contours.size(), 3u);  // the body, and arms that the view may cut off
  double area = 0;
  for (const auto& contour : contours) area += cv::contourArea(contour);
  const SyntheticUser user(standingPose());
  EXPECT_NEAR(area, cv::countNonZero(user.renderMask(cameraRing(5)[0])), 0.05 * area);
}

TEST(Silhouette, AnImageOfTheWrongSizeIsOneClearError) {
  SilhouetteExtractor extractor({640, 480});
  const auto status = extractor.learnBackground(cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(0)));
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().message, "image of 320x240 where the camera's calibration says 640x480");
  auto mask = extractor.extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)));
  ASSERT_FALSE(mask);
  EXPECT_EQ(mask.error().message, "image of type CV_8UC1 where 8-bit BGR (CV_8UC3) is expected");
}

TEST(Silhouette, AFrameBeforeAnyBackgroundIsAnError) {
  SilhouetteExtractor extractor({64, 48});
  auto mask = extractor.extract(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(0)));
  ASSERT_FALSE(mask);
  EXPECT_EQ(mask.error().message, "no background learnt before the first frame");
}

// Five cameras' extractors with a learnt room each, and one frame of the user in each camera.
struct FiveCameras {
  std::vector<CameraCalibration> cameras = cameraRing(5);
  std::vector<SilhouetteExtractor> extractors;
  std::vector<cv::Mat> images;

  FiveCameras() {
    const SyntheticUser user(standingPose());
    for (int c = 0; c < 5; ++c) {
      const CameraCalibration& camera = cameras[static_cast<std::size_t>(c)];
      extractors.emplace_back(camera.imageSize);
      for (std::uint64_t n = 0; n < 3; ++n)
        EXPECT_TRUE(
            extractors.back().learnBackground(renderBackground(camera.imageSize, c, 6.0, n + 1)));
      images.push_back(renderUserImage(user, camera, c, 6.0, 99));
    }
  }
};

TEST(Silhouettes, EveryCameraOnTwoThreadsGivesEachCamerasOwnMask) {
  FiveCameras rig;
  std::vector<cv::Mat> one;
  for (std::size_t c = 0; c < 5; ++c) one.push_back(*rig.extractors[c].extract(rig.images[c]));
  for (int threads : {1, 2, 8}) {
    auto masks = extractSilhouettes(rig.extractors, rig.images, threads);
    ASSERT_TRUE(masks) << masks.error().message;
    ASSERT_EQ(masks->size(), 5u);
    for (std::size_t c = 0; c < 5; ++c)
      EXPECT_EQ(cv::countNonZero((*masks)[c] != one[c]), 0) << "camera " << c << ", " << threads;
  }
}

TEST(Silhouettes, AWrongImageOrCountIsOneErrorNamingTheCamera) {
  FiveCameras rig;
  rig.images[3] = cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(0));
  auto masks = extractSilhouettes(rig.extractors, rig.images, 2);
  ASSERT_FALSE(masks);
  EXPECT_EQ(masks.error().message,
            "camera 3: image of 320x240 where the camera's calibration says 640x480");
  rig.images.pop_back();
  masks = extractSilhouettes(rig.extractors, rig.images, 2);
  ASSERT_FALSE(masks);
  EXPECT_EQ(masks.error().message, "4 images for 5 cameras");
}

}  // namespace
}  // namespace vrflow::camera
