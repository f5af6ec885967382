#include "vrflow/camera/silhouette.hpp"

#include <opencv2/imgproc.hpp>
#include <string>

#include "parallel_parts.hpp"

namespace vrflow::camera {

SilhouetteExtractor::SilhouetteExtractor(cv::Size imageSize, const SilhouetteSettings& settings)
    : size_(imageSize), settings_(settings) {
  if (settings_.model == SilhouetteSettings::Model::kMog2)
    mog2_ = cv::createBackgroundSubtractorMOG2(500, 16.0, false);
  if (settings_.morphologyRadius > 0)
    kernel_ = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * settings_.morphologyRadius + 1,
                                                            2 * settings_.morphologyRadius + 1});
}

Status SilhouetteExtractor::checkImage(const cv::Mat& image) const {
  if (image.size() != size_)
    return makeError("image of " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                     " where the camera's calibration says " + std::to_string(size_.width) + "x" +
                     std::to_string(size_.height));
  if (image.type() != CV_8UC3)
    return makeError("image of type " + cv::typeToString(image.type()) +
                     " where 8-bit BGR (CV_8UC3) is expected");
  return {};
}

Status SilhouetteExtractor::learnBackground(const cv::Mat& image) {
  if (auto status = checkImage(image); !status) return status;
  if (mog2_) {
    cv::Mat ignored;
    mog2_->apply(image, ignored, -1);
    return {};
  }
  if (backgroundSum_.empty()) backgroundSum_ = cv::Mat::zeros(size_, CV_32FC3);
  cv::accumulate(image, backgroundSum_);
  ++backgroundCount_;
  backgroundSum_.convertTo(background_, CV_8UC3, 1.0 / backgroundCount_);
  return {};
}

Result<cv::Mat> SilhouetteExtractor::extract(const cv::Mat& image,
                                             std::vector<std::vector<cv::Point>>* contours) {
  if (auto status = checkImage(image); !status) return status.error();
  cv::Mat mask;
  if (mog2_) {
    mog2_->apply(image, mask, 0);  // the model is not updated by the user's frames
  } else {
    if (backgroundCount_ == 0) return makeError("no background learnt before the first frame");
    cv::Mat difference;
    cv::absdiff(image, background_, difference);
    cv::Mat channels[3];
    cv::split(difference, channels);
    cv::max(channels[0], channels[1], mask);
    cv::max(mask, channels[2], mask);
  }
  cv::threshold(mask, mask, mog2_ ? 127 : settings_.threshold, 255, cv::THRESH_BINARY);
  if (!kernel_.empty()) {
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel_);
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, kernel_);
  }
  // Keep the large components: their outer contours, filled; without fillHoles the holes come
  // back from the thresholded mask.
  std::vector<std::vector<cv::Point>> found;
  cv::findContours(mask, found, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  const double minArea = settings_.minAreaFraction * size_.area();
  cv::Mat kept(size_, CV_8UC1, cv::Scalar(0));
  std::vector<std::vector<cv::Point>> outlines;
  for (auto& outline : found)
    if (cv::contourArea(outline) >= minArea) outlines.push_back(std::move(outline));
  cv::drawContours(kept, outlines, -1, 255, cv::FILLED);
  if (!settings_.fillHoles) cv::bitwise_and(kept, mask, kept);
  if (contours) *contours = std::move(outlines);
  return kept;
}

Result<std::vector<cv::Mat>> extractSilhouettes(std::vector<SilhouetteExtractor>& extractors,
                                                const std::vector<cv::Mat>& images, int threads) {
  if (images.size() != extractors.size())
    return makeError(std::to_string(images.size()) + " images for " +
                     std::to_string(extractors.size()) + " cameras");
  std::vector<Result<cv::Mat>> masks(images.size(), cv::Mat());
  forParts(threads, images.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) masks[c] = extractors[c].extract(images[c]);
  });
  std::vector<cv::Mat> out;
  for (std::size_t c = 0; c < masks.size(); ++c) {
    if (!masks[c])
      return makeError("camera " + std::to_string(c) + ": " + masks[c].error().message);
    out.push_back(std::move(*masks[c]));
  }
  return out;
}

}  // namespace vrflow::camera
