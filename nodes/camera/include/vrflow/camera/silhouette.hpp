#pragma once
// Silhouettes: the user's binary mask in one camera's images, from a background model
// (a learnt static background or OpenCV's BackgroundSubtractorMOG2), a threshold, a morphological
// opening and closing and the large connected components only.

#include <opencv2/core.hpp>
#include <opencv2/video/background_segm.hpp>
#include <vector>

#include "vrflow/base/result.hpp"

namespace vrflow::camera {

/// How a silhouette is extracted.
struct SilhouetteSettings {
  enum class Model { kStaticBackground, kMog2 };
  Model model = Model::kStaticBackground;
  double threshold = 30;     ///< static model: a pixel is foreground when a channel differs more
  int morphologyRadius = 1;  ///< opening then closing with an ellipse of this radius (0: none)
  double minAreaFraction = 0.002;  ///< components smaller than this fraction of the image go
  bool fillHoles = true;           ///< holes inside a kept component are filled
};

/// One camera's silhouette extractor (not thread-safe; one per camera).
class SilhouetteExtractor {
 public:
  SilhouetteExtractor(cv::Size imageSize, const SilhouetteSettings& settings = {});

  /// Adds an image of the empty scene to the background model.
  Status learnBackground(const cv::Mat& image);
  /// The mask (CV_8UC1, 255 inside) of `image`; with `contours`, the kept components' outlines.
  Result<cv::Mat> extract(const cv::Mat& image,
                          std::vector<std::vector<cv::Point>>* contours = nullptr);

 private:
  Status checkImage(const cv::Mat& image) const;

  cv::Size size_;
  SilhouetteSettings settings_;
  cv::Mat backgroundSum_;  // CV_32FC3
  int backgroundCount_ = 0;
  cv::Mat background_;  // CV_8UC3, the mean
  cv::Ptr<cv::BackgroundSubtractorMOG2> mog2_;
  cv::Mat kernel_;
};

/// One frame's masks, extractors[c] on images[c], the cameras shared over `threads` oneTBB
/// threads (each extractor on one of them); the first camera's error in camera order.
Result<std::vector<cv::Mat>> extractSilhouettes(std::vector<SilhouetteExtractor>& extractors,
                                                const std::vector<cv::Mat>& images,
                                                int threads = 1);

}  // namespace vrflow::camera
