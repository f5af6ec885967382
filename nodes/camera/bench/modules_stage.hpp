#pragma once
// The `modules` stage of vrflow-bench-camera: the camera chain as modules, through `vrflow run`.
#include <opencv2/core.hpp>
#include <string>

namespace vrflow::camera {

/// Per-frame times of one run of the module chain.
struct ModuleChainTimes {
  double wallMsPerFrame = 0;  ///< the run's wall time over its iterations (start-up included)
  double captureMs = 0;       ///< the slowest capture module's mean compute (its rendering)
  double silhouetteMs = 0;    ///< the slowest silhouette module's mean compute per iteration
  double hullMs = 0;          ///< the hull module's mean compute per iteration
  double animatorMs = 0;      ///< the user animator's (distance field, mesh, velocity)
  std::string error;          ///< why the run failed, empty when it ran
};

/// Runs `cameras` synthetic captures -> silhouettes -> merge -> one hull module of `voxels`^3 ->
/// the user animator for `iterations` frames with the `vrflow` beside this program, in a temporary
/// folder.
ModuleChainTimes runModuleChain(int cameras, cv::Size size, int voxels, int iterations);

}  // namespace vrflow::camera
