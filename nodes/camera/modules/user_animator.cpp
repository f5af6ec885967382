// camera/user-animator: the captured user as a kinematic object. Each iteration it gathers the
// `slabs` hull slabs of one frame from its `hull` input into the voxel model and publishes one
// object of type `user` on `objects`: position, bounds, and as dynamic resources its mesh, its
// signed distance field and the velocity of its surface, estimated from this frame's distance
// field and the previous one (user_velocity.hpp), stamped with the capture time and iteration of
// the frame (capture_stamps.hpp). It takes no events: nothing pushes the user.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/camera/distance_field.hpp"
#include "vrflow/camera/hull_message.hpp"
#include "vrflow/camera/user_object.hpp"
#include "vrflow/camera/user_velocity.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

namespace {

using namespace vrflow;

// The frame's voxel model from the slabs of `message`: an error unless exactly `slabs` slabs of
// one grid arrive and cover it.
Result<camera::VoxelGrid> gather(const msg::MessageView& message, int slabs) {
  std::optional<camera::VoxelGrid> grid;
  int count = 0, covered = 0;
  for (const auto chunk : message) {
    const auto resource = chunk.asResource();
    if (!resource) continue;
    auto slab = camera::readHullSlab(*resource);
    if (!slab) return Error{slab.error().message};
    if (!grid) grid.emplace(slab->spec);
    if (auto status = camera::gatherHullSlab(*slab, *grid); !status)
      return Error{"resource " + std::to_string(resource->id()) + ": " + status.error().message};
    ++count;
    covered += slab->zEnd - slab->zBegin;
  }
  if (count != slabs || !grid || covered != grid->spec.nz)
    return Error{"received " + std::to_string(count) + " hull slabs covering " +
                 std::to_string(covered) + " z layers" +
                 (grid ? " of " + std::to_string(grid->spec.nz) : std::string()) +
                 "; parameter 'slabs' expects " + std::to_string(slabs) +
                 " covering the grid (check the hull modules and their connections)"};
  return std::move(*grid);
}

}  // namespace

int main() {
  const char* program = "vrflow-camera-user-animator";
  Module module;
  auto& hull = module.addInput("hull");
  auto& objects = module.addOutput("objects");
  if (!initOrReport(module, program)) return 2;
  const auto& params = module.params();
  const int slabs = static_cast<int>(params.getInt("slabs"));
  const double fallbackDt = params.getFloat("dt");
  const bool withVelocity = params.getBool("velocity");
  camera::SurfaceVelocitySettings velocitySettings;
  velocitySettings.smoothing = static_cast<int>(params.getInt("velocity-smoothing"));
  velocitySettings.band = params.getFloat("velocity-band");
  velocitySettings.frames = static_cast<int>(params.getInt("velocity-frames"));
  const double fieldReach = params.getFloat("field-reach");
  const int threads = static_cast<int>(params.getInt("threads"));
  // The band the field is exact in: what the interactors read (field-reach) and what the surface
  // velocity reads (its band and smoothing), with the margin of the readers' samples.
  auto fieldBand = [&](const camera::GridSpec& spec) {
    if (!(fieldReach > 0)) return std::numeric_limits<double>::infinity();
    const double velocityReach =
        withVelocity ? velocitySettings.band + velocitySettings.smoothing * spec.voxelSize : 0.0;
    return camera::fieldBandFor(std::max(fieldReach, velocityReach), spec);
  };
  camera::SurfaceChangeHistory history;
  camera::UserIds ids{module.newId(), module.newId(), module.newId(), module.newId()};
  std::optional<camera::UserFrame> previous;
  double previousTime = 0;
  while (module.wait()) {
    const Message& received = module.get(hull);
    if (!received.valid()) continue;
    auto grid = gather(received.view(), slabs);
    if (!grid) {
      std::fprintf(stderr, "%s: iteration %llu: %s\n", program,
                   static_cast<unsigned long long>(module.iteration()),
                   grid.error().message.c_str());
      return 1;
    }
    camera::UserFrame frame = camera::describeUser(*grid, fieldBand(grid->spec), threads);
    const double time = module.simTime();
    if (withVelocity) {
      const bool sameGrid =
          previous && previous->spec.nx == frame.spec.nx && previous->spec.ny == frame.spec.ny &&
          previous->spec.nz == frame.spec.nz && previous->spec.origin == frame.spec.origin &&
          previous->spec.voxelSize == frame.spec.voxelSize;
      const double dt = time > previousTime ? time - previousTime : fallbackDt;
      if (!sameGrid) history.clear();
      frame.velocity = sameGrid ? camera::surfaceVelocity(frame.spec, previous->sdf, frame.sdf, dt,
                                                          velocitySettings, &history)
                                : std::vector<float>(3 * frame.spec.count(), 0.0f);
    }
    const std::size_t bytes = 4 * frame.sdf.size() + 4 * frame.velocity.size() +
                              12 * frame.mesh.vertices.size() + 12 * frame.mesh.triangles.size() +
                              1024;
    auto out = module.newMessage(bytes);
    out.builder().setSimTime(time);
    out.builder().setTimeStep(received.view().stamps().timeStep);
    camera::copyCaptureStamps(received.view(), out.builder());
    camera::writeUser(out.builder(), ids, frame, !previous.has_value());
    if (!module.put(objects, std::move(out))) break;
    previous = std::move(frame);
    previousTime = time;
  }
  return module.exitStatus();
}
