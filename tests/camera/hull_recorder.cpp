// cameratest/hull-recorder: the test end of a camera chain. Each iteration it gathers the hull
// slabs it receives into the grid and appends the frame to a binary file: u64 iteration, f64
// simulation time, i64 capture time (the capture-ns stamp, -1 when absent), i32 nx ny nz, f64
// origin[3], f64 voxel size, u32 number of slabs, then the nx*ny*nz occupancy bytes.
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

#include "vrflow/camera/hull_message.hpp"
#include "vrflow/camera/image_message.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"

int main() {
  using namespace vrflow;
  Module module;
  const InputPort& hullIn = module.addInput("hull");
  if (!initOrReport(module, "vrflow-cameratest-hull-recorder")) return 2;
  std::ofstream out(module.params().getString("output"), std::ios::binary);
  if (!out) return 1;
  const auto write = [&](const auto& value) {
    out.write(reinterpret_cast<const char*>(&value), sizeof value);
  };
  while (module.wait()) {
    const Message& in = module.get(hullIn);
    std::optional<camera::VoxelGrid> grid;
    std::uint32_t slabs = 0;
    for (const auto chunk : in.view()) {
      const auto resource = chunk.asResource();
      if (!resource) continue;
      auto slab = camera::readHullSlab(*resource);
      if (!slab) {
        std::fprintf(stderr, "hull-recorder: %s\n", slab.error().message.c_str());
        return 1;
      }
      if (!grid) grid.emplace(slab->spec);
      if (auto status = camera::gatherHullSlab(*slab, *grid); !status) return 1;
      ++slabs;
    }
    if (!grid) continue;
    write(module.iteration());
    write(in.view().stamps().simTime);
    write(camera::captureTimeNs(in.view()).value_or(-1));
    write(grid->spec.nx);
    write(grid->spec.ny);
    write(grid->spec.nz);
    for (int a = 0; a < 3; ++a) write(grid->spec.origin[a]);
    write(grid->spec.voxelSize);
    write(slabs);
    out.write(reinterpret_cast<const char*>(grid->occupied.data()),
              static_cast<std::streamsize>(grid->occupied.size()));
    out.flush();
  }
  return module.exitStatus();
}
