#include "vrflow/camera/capture_source.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "vrflow/camera/synthetic_user.hpp"

namespace vrflow::camera {

namespace {

const char* const kSourceForms =
    "a source is 'synthetic', '/dev/videoN', an image sequence 'dir/img_%04d.png' or "
    "'dir/*.png', or a video file";

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The checks every source's frames pass: an image of the calibration's size, in BGR.
Result<CapturedFrame> checkedFrame(cv::Mat image, std::int64_t captureNs, const cv::Size& size,
                                   std::uint64_t frame) {
  if (image.size() != size)
    return Error{"frame " + std::to_string(frame) + " is " + std::to_string(image.cols) + "x" +
                 std::to_string(image.rows) + ", the calibration says " +
                 std::to_string(size.width) + "x" + std::to_string(size.height)};
  if (image.depth() != CV_8U)
    return Error{"frame " + std::to_string(frame) + " is not an 8-bit image"};
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  return CapturedFrame{image, captureNs};
}

class SyntheticSource final : public CaptureSource {
 public:
  SyntheticSource(ColourCamera camera, KeyframeTrack track, const CaptureSettings& settings)
      : camera_(std::move(camera)), track_(std::move(track)), settings_(settings) {}
  Result<CapturedFrame> next() override {
    const std::uint64_t k = frame_++;
    const double time = static_cast<double>(k) / settings_.fps;
    std::optional<SyntheticUser> user;
    if (k >= static_cast<std::uint64_t>(settings_.emptyFrames)) user.emplace(track_.poseAt(time));
    auto image = camera_.render(user ? &*user : nullptr, k);
    if (!image) return image.error();
    return CapturedFrame{*image, std::llround(time * 1e9)};
  }

 private:
  ColourCamera camera_;
  KeyframeTrack track_;
  CaptureSettings settings_;
  std::uint64_t frame_ = 0;
};

// A V4L2 device, a video file or a printf image sequence, through cv::VideoCapture.
class VideoSource final : public CaptureSource {
 public:
  VideoSource(std::unique_ptr<cv::VideoCapture> capture, cv::Size size)
      : capture_(std::move(capture)), size_(size) {}
  Result<CapturedFrame> next() override {
    const std::uint64_t k = frame_++;
    cv::Mat image;
    if (!capture_->read(image) || image.empty())
      return Error{
          "stopped delivering: no frame " + std::to_string(k) + " (" +
          (k == 0 ? std::string("it gave none") : "it gave " + std::to_string(k) + " frames") +
          "; the file ended or the device is gone)"};
    return checkedFrame(image, steadyNowNs(), size_, k);
  }

 private:
  std::unique_ptr<cv::VideoCapture> capture_;
  cv::Size size_;
  std::uint64_t frame_ = 0;
};

// The files a glob names, in sorted order, read with cv::imread.
class GlobSource final : public CaptureSource {
 public:
  GlobSource(std::vector<cv::String> files, cv::Size size)
      : files_(std::move(files)), size_(size) {}
  Result<CapturedFrame> next() override {
    const std::uint64_t k = frame_++;
    if (k >= files_.size())
      return Error{"stopped delivering: no frame " + std::to_string(k) + " (the sequence has " +
                   std::to_string(files_.size()) + " files)"};
    cv::Mat image = cv::imread(files_[k], cv::IMREAD_COLOR);
    if (image.empty()) return Error{"'" + files_[k] + "' is not an image OpenCV can read"};
    return checkedFrame(image, steadyNowNs(), size_, k);
  }

 private:
  std::vector<cv::String> files_;
  cv::Size size_;
  std::uint64_t frame_ = 0;
};

Result<std::unique_ptr<CaptureSource>> openSynthetic(const CaptureSettings& settings) {
  if (settings.keyframes.empty())
    return Error{"the synthetic source needs a keyframes file (parameter 'keyframes')"};
  if (!(settings.fps > 0) || !std::isfinite(settings.fps))
    return Error{"the synthetic source needs fps > 0"};
  auto track = KeyframeTrack::load(settings.keyframes);
  if (!track) return track.error();
  auto camera = ColourCamera::create(settings.calibration, settings.colour);
  if (!camera) return camera.error();
  return std::unique_ptr<CaptureSource>(
      new SyntheticSource(std::move(*camera), std::move(*track), settings));
}

Result<std::unique_ptr<CaptureSource>> openVideo(const std::string& name, int apiPreference,
                                                 const cv::Size& size) {
  auto capture = std::make_unique<cv::VideoCapture>();
  bool opened = false;
  try {
    opened = capture->open(name, apiPreference);
  } catch (const cv::Exception& e) {
    return Error{"OpenCV cannot open it: " + std::string(e.what())};
  }
  if (!opened) return Error{"OpenCV cannot open it (" + std::string(kSourceForms) + ")"};
  return std::unique_ptr<CaptureSource>(new VideoSource(std::move(capture), size));
}

}  // namespace

Result<std::unique_ptr<CaptureSource>> openCaptureSource(const CaptureSettings& settings) {
  const std::string& source = settings.source;
  const cv::Size size = settings.calibration.imageSize;
  auto named =
      [&](Result<std::unique_ptr<CaptureSource>> opened) -> Result<std::unique_ptr<CaptureSource>> {
    if (!opened) return Error{"source '" + source + "': " + opened.error().message};
    return opened;
  };
  if (source == "synthetic") return named(openSynthetic(settings));
  if (std::regex_match(source, std::regex("/dev/video[0-9]+")))
    return named(openVideo(source, cv::CAP_V4L2, size));
  if (source.find('%') != std::string::npos) return named(openVideo(source, cv::CAP_IMAGES, size));
  if (source.find_first_of("*?[") != std::string::npos) {
    std::vector<cv::String> files;
    try {
      cv::glob(source, files, false);
    } catch (const cv::Exception&) {
      files.clear();
    }
    if (files.empty()) return named(Error{"no file matches the pattern"});
    std::sort(files.begin(), files.end());
    return std::unique_ptr<CaptureSource>(new GlobSource(std::move(files), size));
  }
  std::error_code ec;
  if (source.empty() || !std::filesystem::is_regular_file(source, ec))
    return named(Error{std::string("not a regular file, and ") + kSourceForms});
  return named(openVideo(source, cv::CAP_ANY, size));
}

}  // namespace vrflow::camera
