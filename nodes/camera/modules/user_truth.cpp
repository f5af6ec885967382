// camera/user-truth: the ground-truth hull. Each iteration it poses the synthetic user from its
// keyframes at the iteration's time and sends the exact voxelisation of its capsules as `slabs`
// hull slabs (hull_message.hpp), the message a hull module sends from cameras: the interactions
// can be run and tested without the vision chain.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>

#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/camera/hull_message.hpp"
#include "vrflow/camera/synthetic_user.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  const char* program = "vrflow-camera-user-truth";
  Module module;
  auto& hull = module.addOutput("hull");
  if (!initOrReport(module, program)) return 2;
  const auto& params = module.params();
  const double dt = params.getFloat("dt");
  const int cells = static_cast<int>(params.getInt("cells"));
  const int slabs = static_cast<int>(params.getInt("slabs"));
  if (slabs > cells) {
    std::fprintf(stderr, "%s: parameter 'slabs' (%d) exceeds 'cells' (%d)\n", program, slabs,
                 cells);
    return 2;
  }
  const msg::Vec3 origin = params.getVec3("volume-origin");
  const camera::GridSpec spec = camera::GridSpec::cube({origin[0], origin[1], origin[2]},
                                                       params.getFloat("volume-edge"), cells);
  std::optional<camera::KeyframeTrack> track;
  if (const auto path = params.getString("keyframes"); !path.empty()) {
    auto loaded = camera::KeyframeTrack::load(path);
    if (!loaded) {
      std::fprintf(stderr, "%s: %s\n", program, loaded.error().message.c_str());
      return 2;
    }
    track = std::move(*loaded);
  }
  std::vector<std::uint64_t> ids(static_cast<std::size_t>(slabs));
  for (auto& id : ids) id = module.newId();
  while (module.wait()) {
    const double time = static_cast<double>(module.iteration()) * dt;
    const camera::SyntheticUser user(track ? track->poseAt(time) : camera::standingPose());
    const camera::VoxelGrid grid = user.voxelize(spec);
    auto out = module.newMessage(grid.occupied.size() + 256 + 96 * ids.size());
    auto& builder = out.builder();
    builder.setSimTime(time);
    builder.setTimeStep(dt);
    // The frame's capture stamps, as a capture module's (capture_stamps.hpp).
    builder.addInt64Stamp(camera::kCaptureStamp,
                          static_cast<std::int64_t>(std::llround(time * 1e9)));
    builder.addInt64Stamp(camera::kCaptureIterationStamp,
                          static_cast<std::int64_t>(module.iteration()));
    for (int s = 0; s < slabs; ++s)
      camera::addHullSlab(builder, ids[static_cast<std::size_t>(s)], grid, s * cells / slabs,
                          (s + 1) * cells / slabs);
    if (!module.put(hull, std::move(out))) break;
  }
  return module.exitStatus();
}
