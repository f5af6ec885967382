// vrflow-bench-fluid-surface: the liquid's surface against its particles on the paper scene's
// pool (32 x 64 x 32 cells of 6.25 cm, 0.85 m deep, a column of water released at one end so
// that the surface moves). Per payload (the particles; the surface at 1 and 2 voxels per cell),
// one JSON line: bytes of the `fluid` message per frame, whole (one region) and per tile of a
// 2 x 2 wall looking down on the pool (4 x 1 x 4 regions, each tile the 4 under it, as
// examples/routed_wall/routed_fluid_wall.xml), ms per extraction against ms per fluid step,
// triangles. The same steps feed every payload. With --png, a frame of the last state drawn by
// the viewer's renderer.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "vrflow/fluid/solver.hpp"
#include "vrflow/fluid/surface.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/viewer/renderer.hpp"

namespace {

using namespace vrflow;
using Clock = std::chrono::steady_clock;

constexpr std::array<int, 3> kRegions{4, 1, 4};

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown";
}

// The module's `fluid` message for the regions listed in `which` (payload `meshes[r]`, object
// r + 1 naming resource r + 100), as it sends them after iteration 0; its size in bytes.
std::size_t messageBytes(const std::vector<fluid::SurfaceMesh>& meshes,
                         const std::vector<msg::Aabb>& bounds, const std::vector<int>& which,
                         bool surface, msg::VectorSink* keep = nullptr) {
  msg::VectorSink local;
  msg::VectorSink& sink = keep ? *keep : local;
  msg::MessageBuilder b(sink);
  for (const int r : which) {
    const auto k = static_cast<std::size_t>(r);
    b.addMesh(100 + k, true, meshes[k].xyz, meshes[k].indices);
    b.addObject(1 + k, msg::fluidType(), msg::ObjectOp::Add)
        .set(msg::FluidParam::kBounds, bounds[k])
        .set(surface ? msg::FluidParam::kSurface : msg::FluidParam::kParticles,
             std::uint64_t{100 + k});
  }
  return b.finish();
}

struct Payload {
  std::string name;
  int voxelsPerCell = 0;  // 0: particles
  fluid::SurfaceMethod method = fluid::SurfaceMethod::Density;
  double bytesWhole = 0, bytesTileMax = 0, bytesTileMean = 0, extractMs = 0, triangles = 0;
  std::vector<double> extractSamples;
};

}  // namespace

int main(int argc, char** argv) {
  int steps = 120;
  int every = 10;
  std::string png;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps" && i + 1 < argc) {
      steps = std::max(1, std::atoi(argv[++i]));
    } else if (arg == "--png" && i + 1 < argc) {
      png = argv[++i];
    } else {
      std::fprintf(stderr, "usage: vrflow-bench-fluid-surface [--steps N] [--png OUT.png]\n");
      return 2;
    }
  }
  fluid::FluidSettings s;
  s.cellSize = 0.0625;
  s.origin = {0.25, 0.0, -1.0};
  auto created = fluid::FluidSolver::create(s);
  if (!created) {
    std::fprintf(stderr, "%s\n", created.error().message.c_str());
    return 1;
  }
  auto solver = std::move(*created);
  if (!solver->addLiquidBox({{0.25, 0.0, -1.0}, {2.25, 0.85, 1.0}}).ok() ||
      !solver->addLiquidBox({{1.75, 0.85, -1.0}, {2.25, 1.6, 1.0}}).ok()) {
    std::fprintf(stderr, "cannot fill the pool\n");
    return 1;
  }
  const msg::Aabb grid = solver->bounds();
  // The particles, the surface by density at 1 and 2 voxels per cell, by spheres at 2.
  std::vector<Payload> payloads(4);
  payloads[0].name = "particles";
  for (const std::size_t k : {1, 2, 3}) {
    payloads[k].name = "surface";
    payloads[k].voxelsPerCell = k == 1 ? 1 : 2;
    payloads[k].method = k == 3 ? fluid::SurfaceMethod::Spheres : fluid::SurfaceMethod::Density;
  }
  double stepMs = 0;
  int samples = 0;
  for (int step = 1; step <= steps; ++step) {
    const auto start = Clock::now();
    if (auto done = solver->step(0.01, {}); !done) {
      std::fprintf(stderr, "%s\n", done.error().message.c_str());
      return 1;
    }
    stepMs += msSince(start);
    if (step % every != 0) continue;
    ++samples;
    const auto& xyz = solver->particlePositions();
    for (auto& p : payloads) {
      std::vector<fluid::SurfaceMesh> meshes;
      std::vector<msg::Aabb> bounds;
      fluid::SurfaceMesh whole;
      if (p.voxelsPerCell == 0) {
        // Particles: split as the module does (the box holding each particle).
        whole.xyz = xyz;
        meshes.assign(16, {});
        bounds.assign(16, grid);
        for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
          int r = 0, stride = 1;
          for (std::size_t a = 0; a < 3; ++a) {
            const double f = (xyz[i + a] - grid.min[a]) / (grid.max[a] - grid.min[a]);
            const int k = std::clamp(static_cast<int>(f * kRegions[a]), 0, kRegions[a] - 1);
            r += k * stride;
            stride *= kRegions[a];
          }
          auto& m = meshes[static_cast<std::size_t>(r)].xyz;
          m.insert(m.end(), xyz.begin() + static_cast<std::ptrdiff_t>(i),
                   xyz.begin() + static_cast<std::ptrdiff_t>(i + 3));
        }
      } else {
        const auto start2 = Clock::now();
        auto settings = fluid::surfaceSettings(s, p.voxelsPerCell);
        settings.method = p.method;
        auto mesh = fluid::extractSurface(xyz, settings);
        const auto regions = fluid::splitSurface(*mesh, grid, kRegions);
        p.extractSamples.push_back(msSince(start2));
        whole = std::move(*mesh);
        for (const auto& region : regions) {
          meshes.push_back(region.mesh);
          bounds.push_back(region.bounds);
        }
        p.triangles += static_cast<double>(whole.triangleCount());
      }
      const bool surface = p.voxelsPerCell > 0;
      p.bytesWhole += static_cast<double>(messageBytes({whole}, {grid}, {0}, surface));
      // Tile (c, r) of the 2 x 2 wall seen from above sees the regions x in {2c, 2c + 1},
      // z in {2r, 2r + 1}.
      double most = 0, sum = 0;
      for (int tile = 0; tile < 4; ++tile) {
        std::vector<int> which;
        for (int z = 0; z < 2; ++z) {
          for (int x = 0; x < 2; ++x)
            which.push_back((2 * (tile % 2) + x) + 4 * (2 * (tile / 2) + z));
        }
        const auto bytes = static_cast<double>(messageBytes(meshes, bounds, which, surface));
        most = std::max(most, bytes);
        sum += bytes;
      }
      p.bytesTileMax += most;
      p.bytesTileMean += sum / 4;
    }
  }
  const double particleBytes = payloads[0].bytesTileMean / samples;
  for (auto& p : payloads) {
    double extract = 0;
    if (!p.extractSamples.empty()) {
      std::sort(p.extractSamples.begin(), p.extractSamples.end());
      extract = p.extractSamples[p.extractSamples.size() / 2];
    }
    std::printf(
        "{\"bench\":\"fluid-surface\",\"grid\":\"32x64x32\",\"particles\":%zu,\"payload\":\"%s\","
        "\"method\":\"%s\",\"voxels_per_cell\":%d,\"frames\":%d,\"bytes_per_frame\":%.0f,\"tiles\":"
        "4,"
        "\"bytes_per_tile_per_frame\":%.0f,\"bytes_per_tile_per_frame_max\":%.0f,"
        "\"less_than_particles_per_tile\":%.2f,\"triangles\":%.0f,\"extract_ms_median\":%.2f,"
        "\"fluid_step_ms_mean\":%.2f,\"machine\":\"%s\"}\n",
        solver->particleCount(), p.name.c_str(),
        p.voxelsPerCell == 0                        ? "-"
        : p.method == fluid::SurfaceMethod::Density ? "density"
                                                    : "spheres",
        p.voxelsPerCell, samples, p.bytesWhole / samples, p.bytesTileMean / samples,
        p.bytesTileMax / samples, particleBytes / (p.bytesTileMean / samples),
        p.triangles / samples, extract, stepMs / steps, machine().c_str());
  }
  if (png.empty()) return 0;
  // The last state's surface (2 voxels per cell) as the viewer draws it.
  auto mesh = fluid::extractSurface(solver->particlePositions(), fluid::surfaceSettings(s, 2));
  msg::VectorSink sink;
  const auto size = messageBytes({*mesh}, {grid}, {0}, true, &sink);
  auto message = msg::MessageView::parse(std::span(sink.buffer()).first(size));
  if (!message) return 1;
  viewer::SceneCache scene;
  scene.apply(*message);
  viewer::RenderSettings settings;
  settings.supersample = 2;
  auto renderer = viewer::Renderer::create(settings);
  if (!renderer) return 1;
  viewer::Camera camera;
  camera.eye = {-0.4, 2.0, 3.0};
  camera.target = {1.25, 0.4, 0.0};
  auto image = renderer->render(scene, camera);
  if (!image || !viewer::writePng(png, *image)) return 1;
  return 0;
}
