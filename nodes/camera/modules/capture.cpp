// camera/capture: one camera's images (synthetic, an image sequence, a video file or a V4L2
// device) as image resources (image_message.hpp) stamped with their capture time and iteration.
#include <cmath>
#include <cstdio>
#include <string>

#include "module_error.hpp"
#include "vrflow/camera/capture_source.hpp"
#include "vrflow/camera/image_message.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace {
constexpr const char* kProgram = "vrflow-camera-capture";
}

int main() {
  using namespace vrflow;
  Module module;
  const OutputPort& imageOut = module.addOutput("image");
  if (!initOrReport(module, kProgram)) return 2;
  const auto& params = module.params();
  const auto fail = [&](const std::string& why) {
    return camera::moduleError(module, kProgram, why);
  };
  camera::CaptureSettings settings;
  settings.source = params.getString("source");
  auto calibration = camera::loadCalibration(params.getString("calibration"));
  if (!calibration) return fail("parameter 'calibration': " + calibration.error().message);
  settings.calibration = *calibration;
  settings.keyframes = params.getString("keyframes");
  settings.fps = params.getFloat("fps");
  settings.emptyFrames = static_cast<int>(params.getInt("empty-frames"));
  settings.colour.roomSeed = static_cast<int>(params.getInt("room-seed"));
  settings.colour.noise = params.getFloat("noise");
  auto source = camera::openCaptureSource(settings);
  if (!source) return fail(source.error().message);
  const std::uint64_t resourceId = module.newId();
  const std::size_t imageBytes =
      static_cast<std::size_t>(settings.calibration.imageSize.area()) * 3;
  while (module.wait()) {
    auto frame = (*source)->next();
    if (!frame) return fail("source '" + settings.source + "': " + frame.error().message);
    auto out = module.newMessage(imageBytes + 512);
    auto& builder = out.builder();
    builder.setSimTime(static_cast<double>(module.iteration()) / settings.fps);
    builder.setTimeStep(1.0 / settings.fps);
    builder.addInt64Stamp(camera::kCaptureStamp, frame->captureNs);
    builder.addInt64Stamp(camera::kCaptureIterationStamp,
                          static_cast<std::int64_t>(module.iteration()));
    camera::addImage(builder, resourceId, frame->image);
    if (!module.put(imageOut, std::move(out))) break;
  }
  return module.exitStatus();
}
