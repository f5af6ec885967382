// camera/hull: the visual hull of one frame, carved from the masks of every camera, or one z
// slab of it (`slab` K/N) so that several hull modules share the grid; sent as a hull slab
// (hull_message.hpp). The masks arrive as one message (a merge filter joins the silhouette
// modules' outputs, camera n's mask n-th), in the order of `calibrations`.
#include <cstdio>
#include <regex>
#include <string>
#include <vector>

#include "module_error.hpp"
#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/hull_message.hpp"
#include "vrflow/camera/image_message.hpp"
#include "vrflow/camera/visual_hull.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace {
constexpr const char* kProgram = "vrflow-camera-hull";
}

int main() {
  using namespace vrflow;
  Module module;
  const InputPort& masksIn = module.addInput("masks");
  const OutputPort& hullOut = module.addOutput("hull");
  if (!initOrReport(module, kProgram)) return 2;
  const auto& params = module.params();
  const auto fail = [&](const std::string& why) {
    return camera::moduleError(module, kProgram, why);
  };
  auto files = camera::calibrationFiles(params.getString("calibrations"),
                                        params.getString("calibration-list"));
  if (!files) return fail(files.error().message);
  std::vector<camera::CameraCalibration> cameras;
  for (const auto& [file, parameter] : *files) {
    auto calibration = camera::loadCalibration(file);
    if (!calibration) return fail(parameter + ": " + calibration.error().message);
    cameras.push_back(*calibration);
  }
  const auto cells = static_cast<int>(params.getInt("cells"));
  const auto origin = params.getVec3("origin");
  const camera::GridSpec spec =
      camera::GridSpec::cube({origin[0], origin[1], origin[2]}, params.getFloat("edge"), cells);
  const std::string slab = params.getString("slab");
  std::smatch parts;
  if (!std::regex_match(slab, parts, std::regex("([0-9]{1,4})/([0-9]{1,4})")) ||
      std::stoi(parts[2]) < 1 || std::stoi(parts[1]) >= std::stoi(parts[2]) ||
      std::stoi(parts[2]) > cells)
    return fail("parameter 'slab': '" + slab + "' is not K/N with 0 <= K < N <= cells (" +
                std::to_string(cells) + ")");
  const int k = std::stoi(parts[1]), n = std::stoi(parts[2]);
  const int zBegin = k * cells / n, zEnd = (k + 1) * cells / n;
  // Threads of the carving (oneTBB, layers of blocks): the bits do not depend on them.
  const auto threads = static_cast<int>(params.getInt("threads"));
  camera::VoxelGrid hull(spec);
  const std::uint64_t resourceId = module.newId();
  std::vector<camera::MaskView> views(cameras.size());
  while (module.wait()) {
    const Message& in = module.get(masksIn);
    if (!in.valid()) continue;
    auto masks = camera::readImages(in.view());
    if (!masks) return fail("input 'masks': " + masks.error().message);
    if (masks->size() != cameras.size())
      return fail("input 'masks': " + std::to_string(masks->size()) + " masks for " +
                  std::to_string(cameras.size()) +
                  " calibrations (merge one mask per camera, "
                  "in the order of 'calibrations')");
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      const cv::Mat& mask = (*masks)[c];
      if (mask.type() != CV_8UC1 || mask.size() != cameras[c].imageSize)
        return fail("input 'masks': mask " + std::to_string(c) + " is " +
                    std::to_string(mask.cols) + "x" + std::to_string(mask.rows) + " of type " +
                    cv::typeToString(mask.type()) + ", its calibration says " +
                    std::to_string(cameras[c].imageSize.width) + "x" +
                    std::to_string(cameras[c].imageSize.height) + " CV_8UC1");
      views[c].camera = &cameras[c];
      views[c].mask = cv::countNonZero(cameras[c].distortion) > 0
                          ? camera::undistortMask(mask, cameras[c])
                          : mask;
    }
    if (auto status = camera::carveVisualHull(views, zBegin, zEnd, hull, nullptr, threads); !status)
      return fail(status.error().message);
    const auto stamps = in.view().stamps();
    auto out = module.newMessage(camera::kHullSlabHeaderSize +
                                 hull.occupied.size() / static_cast<std::size_t>(n) + 1024);
    out.builder().setSimTime(stamps.simTime);
    out.builder().setTimeStep(stamps.timeStep);
    camera::copyCaptureStamps(in.view(), out.builder());
    camera::addHullSlab(out.builder(), resourceId, hull, zBegin, zEnd);
    if (!module.put(hullOut, std::move(out))) break;
  }
  return module.exitStatus();
}
