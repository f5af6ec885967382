// camera/silhouette: one camera's silhouette masks from its images (the paper's per-camera
// stage): a background model learnt from the first frames, threshold, morphology, the large
// components; optionally their outer contours.
#include "vrflow/camera/silhouette.hpp"

#include <cstdio>
#include <string>

#include "module_error.hpp"
#include "vrflow/camera/calibration.hpp"
#include "vrflow/camera/contour_message.hpp"
#include "vrflow/camera/image_message.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace {
constexpr const char* kProgram = "vrflow-camera-silhouette";
}

int main() {
  using namespace vrflow;
  Module module;
  const InputPort& imageIn = module.addInput("image");
  const OutputPort& maskOut = module.addOutput("mask");
  const OutputPort& contoursOut = module.addOutput("contours");
  if (!initOrReport(module, kProgram)) return 2;
  const auto& params = module.params();
  const auto fail = [&](const std::string& why) {
    return camera::moduleError(module, kProgram, why);
  };
  auto calibration = camera::loadCalibration(params.getString("calibration"));
  if (!calibration) return fail("parameter 'calibration': " + calibration.error().message);
  camera::SilhouetteSettings settings;
  settings.model = params.getString("model") == "mog2"
                       ? camera::SilhouetteSettings::Model::kMog2
                       : camera::SilhouetteSettings::Model::kStaticBackground;
  settings.threshold = params.getFloat("threshold");
  settings.morphologyRadius = static_cast<int>(params.getInt("morphology"));
  settings.minAreaFraction = params.getFloat("min-area");
  settings.fillHoles = params.getBool("fill-holes");
  const auto backgroundFrames = static_cast<std::uint64_t>(params.getInt("background-frames"));
  camera::SilhouetteExtractor extractor(calibration->imageSize, settings);
  const std::uint64_t maskId = module.newId();
  const std::uint64_t contoursId = module.newId();
  const bool wantContours = contoursOut.connected();
  const cv::Mat empty = cv::Mat::zeros(calibration->imageSize, CV_8UC1);
  while (module.wait()) {
    const Message& in = module.get(imageIn);
    if (!in.valid()) continue;
    auto images = camera::readImages(in.view());
    if (!images) return fail("input 'image': " + images.error().message);
    if (images->size() != 1)
      return fail("input 'image': " + std::to_string(images->size()) +
                  " images in one message, one expected (one silhouette module per camera)");
    const cv::Mat& image = images->front();
    cv::Mat mask;
    std::vector<std::vector<cv::Point>> contours;
    if (module.iteration() < backgroundFrames) {
      // Learning the empty scene: nothing is in front of it yet.
      if (auto status = extractor.learnBackground(image); !status)
        return fail("input 'image': " + status.error().message);
      mask = empty;
    } else {
      auto extracted = extractor.extract(image, wantContours ? &contours : nullptr);
      if (!extracted) return fail("input 'image': " + extracted.error().message);
      mask = *extracted;
    }
    const auto stamps = in.view().stamps();
    auto out = module.newMessage(static_cast<std::size_t>(mask.total()) + 512);
    out.builder().setSimTime(stamps.simTime);
    out.builder().setTimeStep(stamps.timeStep);
    camera::copyCaptureStamps(in.view(), out.builder());
    camera::addImage(out.builder(), maskId, mask);
    if (!module.put(maskOut, std::move(out))) break;
    if (wantContours) {
      auto contourMessage = module.newMessage(512);
      contourMessage.builder().setSimTime(stamps.simTime);
      contourMessage.builder().setTimeStep(stamps.timeStep);
      camera::addContours(contourMessage.builder(), contoursId, contours);
      if (!module.put(contoursOut, std::move(contourMessage))) break;
    }
  }
  return module.exitStatus();
}
