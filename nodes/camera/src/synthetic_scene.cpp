#include "vrflow/camera/synthetic_scene.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace vrflow::camera {

namespace {

cv::Mat roomTexture(cv::Size size, int seed) {
  cv::RNG rng(static_cast<std::uint64_t>(seed) * 7919 + 1);
  cv::Mat texture(size, CV_8UC3);
  rng.fill(texture, cv::RNG::UNIFORM, cv::Scalar(40, 40, 40), cv::Scalar(220, 220, 220));
  cv::GaussianBlur(texture, texture, {0, 0}, 3.0);
  // Some furniture: flat rectangles of random colour.
  for (int n = 0; n < 12; ++n) {
    const cv::Point a(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Point b(rng.uniform(0, size.width), rng.uniform(0, size.height));
    cv::rectangle(texture, a, b,
                  cv::Scalar(rng.uniform(90, 200), rng.uniform(90, 200), rng.uniform(60, 200)),
                  cv::FILLED);
  }
  return texture;
}

}  // namespace

void addSensorNoise(cv::Mat& image, double noise, std::uint64_t noiseSeed) {
  if (noise <= 0) return;
  cv::RNG rng(noiseSeed);
  cv::Mat n(image.size(), CV_16SC3);
  rng.fill(n, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(noise));
  cv::Mat wide;
  image.convertTo(wide, CV_16SC3);
  wide += n;
  wide.convertTo(image, CV_8UC3);
}

// Heights (m) of the ring's cameras in turn: low ones see under the arms and the torso, high
// ones over them.
constexpr double kHeights[] = {1.4, 3.4, 0.5, 3.0, 0.8};

std::vector<CameraCalibration> cameraRing(int count, cv::Size size) {
  std::vector<CameraCalibration> cameras;
  const double focal = 650.0 * size.width / 640.0;
  const cv::Vec3d target(0, 1.25, 0.15);
  for (int n = 0; n < count; ++n) {
    const double angle = 2 * CV_PI * n / count;
    const cv::Vec3d eye(2.0 * std::sin(angle), kHeights[n % 5], 2.0 * std::cos(angle));
    cameras.push_back(lookAtCamera(size, focal, eye, target));
  }
  return cameras;
}

GridSpec userVolume(int cells) {
  return GridSpec::cube({-0.7, 0.45, -0.5}, 1.4, cells);
}

cv::Mat renderBackground(cv::Size size, int seed, double noise, std::uint64_t noiseSeed) {
  cv::Mat image = roomTexture(size, seed);
  addSensorNoise(image, noise, noiseSeed);
  return image;
}

cv::Mat renderUserImage(const SyntheticUser& user, const CameraCalibration& camera, int seed,
                        double noise, std::uint64_t noiseSeed) {
  cv::Mat image = roomTexture(camera.imageSize, seed);
  cv::Mat cloth(camera.imageSize, CV_8UC3);
  cv::RNG rng(static_cast<std::uint64_t>(seed) + 101);
  rng.fill(cloth, cv::RNG::UNIFORM, cv::Scalar(10, 20, 150), cv::Scalar(40, 50, 230));
  cloth.copyTo(image, user.renderMask(camera));
  addSensorNoise(image, noise, noiseSeed);
  return image;
}

}  // namespace vrflow::camera
