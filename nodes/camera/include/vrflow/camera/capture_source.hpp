#pragma once
// Where a capture module's images come from: the synthetic user filmed by a ColourCamera, an
// image sequence (a printf pattern or a glob), a video file, or a V4L2 device, the last three
// through cv::VideoCapture / cv::imread. A source that stops delivering is an error.

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/colour_camera.hpp"

namespace vrflow::camera {

/// One frame of a source.
struct CapturedFrame {
  cv::Mat image;               ///< BGR CV_8UC3, the calibration's size
  std::int64_t captureNs = 0;  ///< capture time (kCaptureStamp's meaning, image_message.hpp)
};

/// What a source needs besides its name.
struct CaptureSettings {
  /// `synthetic`, `/dev/videoN`, `dir/img_%04d.png` (printf pattern), `dir/*.png` (glob, sorted)
  /// or a video file.
  std::string source;
  CameraCalibration calibration;  ///< images must have its size
  std::string keyframes;          ///< synthetic: the user's keyframe file
  double fps = 30;                ///< synthetic: frame k shows the user at time k / fps
  int emptyFrames = 0;            ///< synthetic: frames 0..emptyFrames-1 show the empty room
  ColourCameraSettings colour;    ///< synthetic: room texture, noise
};

/// A stream of frames (not thread-safe).
class CaptureSource {
 public:
  virtual ~CaptureSource() = default;
  /// The next frame; an error when the source has none (ended, device gone, unreadable) or it
  /// is not of the calibration's size.
  virtual Result<CapturedFrame> next() = 0;
};

/// Opens `settings.source`; an error (naming the source) when it cannot deliver.
Result<std::unique_ptr<CaptureSource>> openCaptureSource(const CaptureSettings& settings);

}  // namespace vrflow::camera
