#pragma once
// The synthetic camera in colour: the capsule user rendered with OpenGL (OSMesa, Mesa's software
// rasteriser, as the viewer package draws) from a calibrated viewpoint, shaded with the viewer's
// lights, over the textured room of synthetic_scene.hpp, with sensor noise. The projection is the
// calibration's exactly: a glFrustum built from K (any principal point, fx != fy), the pose
// [R | T], then the lens distortion applied to the pinhole render (cv::remap). A pixel shows the
// user when its centre's ray meets the tessellated capsules (48 segments around).

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/synthetic_user.hpp"

namespace vrflow::camera {

/// How the synthetic colour camera films.
struct ColourCameraSettings {
  int roomSeed = 0;    ///< which room texture (renderBackground's seed)
  double noise = 2.0;  ///< sensor noise, standard deviation in grey levels (0: none)
  int segments = 48;   ///< capsule tessellation around the axis
};

/// One calibrated synthetic camera with its own OSMesa context (one per thread at a time).
class ColourCamera {
 public:
  /// Creates the context and the frame buffer of the calibration's image size.
  static Result<ColourCamera> create(const CameraCalibration& calibration,
                                     const ColourCameraSettings& settings = {});
  ColourCamera(ColourCamera&&) noexcept;
  ColourCamera& operator=(ColourCamera&&) noexcept;
  ~ColourCamera();

  /// The room with `user` in it (the empty room when null), BGR CV_8UC3; the noise of frame
  /// `frame` (the same frame gives the same bits).
  Result<cv::Mat> render(const SyntheticUser* user, std::uint64_t frame);

 private:
  struct Impl;
  explicit ColourCamera(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow::camera
