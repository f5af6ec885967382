// vrflow-bench-camera: ms per frame of each stage of the camera chain (silhouettes of every
// camera, hierarchical visual hull, signed distance field, mesh) and of the whole chain, on
// synthetic frames of the moving user, with the straightforward carving (cv::projectPoints of every
// voxel into every mask) measured in the same run as the baseline. One JSON line per case:
// {cameras, width, height, voxels, stage, ms_per_frame, iou, machine}. `--quick`: a smoke run.
// The stages `modules_*` run the chain as modules (capture, silhouette, hull) through `vrflow run`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "modules_stage.hpp"
#include "vrflow/camera/distance_field.hpp"
#include "vrflow/camera/hull_mesh.hpp"
#include "vrflow/camera/silhouette.hpp"
#include "vrflow/camera/synthetic_scene.hpp"
#include "vrflow/camera/visual_hull.hpp"

namespace {

using namespace vrflow::camera;

std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores";
}

// The user waving both hands: frame n of a 1 s motion.
UserPose movingPose(int n, int frames) {
  UserPose pose = standingPose();
  const double phase = 2 * CV_PI * n / frames;
  for (int joint : {5, 6})
    pose[static_cast<std::size_t>(joint)] +=
        cv::Vec3d(0, 0.15 * std::sin(phase), 0.05 * std::cos(phase));
  for (int joint : {9, 10})
    pose[static_cast<std::size_t>(joint)] +=
        cv::Vec3d(0.05 * std::cos(phase), -0.1 * std::sin(phase), 0);
  return pose;
}

struct Frame {
  std::vector<cv::Mat> images;  // one per camera
  VoxelGrid exact;
};

double msPerFrame(int frames, int repeats, const std::function<void(int)>& work) {
  work(0);  // warm the caches and OpenCV's buffers
  double best = 1e30;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int n = 0; n < frames; ++n) work(n);
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count() / frames);
  }
  return best;
}

void print(int cameras, cv::Size size, int voxels, const char* stage, double ms, double iou,
           const std::string& host) {
  std::printf(
      "{\"cameras\": %d, \"width\": %d, \"height\": %d, \"voxels\": %d, \"stage\": \"%s\", "
      "\"ms_per_frame\": %.3f, \"iou\": %s, \"machine\": \"%s\"}\n",
      cameras, size.width, size.height, voxels, stage, ms,
      iou < 0 ? "null" : std::to_string(iou).c_str(), host.c_str());
  std::fflush(stdout);
}

void runCase(int cameraCount, cv::Size size, int voxels, int frames, int repeats, bool baseline,
             const std::string& host) {
  const std::vector<CameraCalibration> cameras = cameraRing(cameraCount, size);
  const GridSpec spec = userVolume(voxels);
  std::vector<SilhouetteExtractor> extractors;
  for (int c = 0; c < cameraCount; ++c) {
    extractors.emplace_back(size);
    for (std::uint64_t n = 0; n < 5; ++n)
      (void)extractors.back().learnBackground(renderBackground(size, c, 4.0, n + 1));
  }
  std::vector<Frame> input;
  for (int n = 0; n < frames; ++n) {
    const SyntheticUser user(movingPose(n, frames));
    Frame frame{{}, user.voxelize(spec)};
    for (int c = 0; c < cameraCount; ++c)
      frame.images.push_back(renderUserImage(user, cameras[static_cast<std::size_t>(c)], c, 4.0,
                                             1000 + static_cast<std::uint64_t>(n)));
    input.push_back(std::move(frame));
  }
  // Each stage's output, kept per frame so the next stage is timed alone.
  std::vector<std::vector<MaskView>> views(static_cast<std::size_t>(frames));
  std::vector<VoxelGrid> hulls(static_cast<std::size_t>(frames), VoxelGrid(spec));
  std::vector<std::vector<float>> fields(static_cast<std::size_t>(frames));
  auto silhouettes = [&](int n) {
    auto& v = views[static_cast<std::size_t>(n)];
    v.clear();
    for (int c = 0; c < cameraCount; ++c)
      v.push_back({&cameras[static_cast<std::size_t>(c)],
                   *extractors[static_cast<std::size_t>(c)].extract(
                       input[static_cast<std::size_t>(n)].images[static_cast<std::size_t>(c)])});
  };
  auto hull = [&](int n) {
    (void)carveVisualHull(views[static_cast<std::size_t>(n)], 0, spec.nz,
                          hulls[static_cast<std::size_t>(n)]);
  };
  auto field = [&](int n) {
    fields[static_cast<std::size_t>(n)] = signedDistanceField(hulls[static_cast<std::size_t>(n)]);
  };
  std::size_t triangles = 0;
  auto mesh = [&](int n) {
    triangles += meshHull(hulls[static_cast<std::size_t>(n)], fields[static_cast<std::size_t>(n)])
                     .triangles.size();
  };
  auto meanIoU = [&] {
    double sum = 0;
    for (int n = 0; n < frames; ++n)
      sum += intersectionOverUnion(hulls[static_cast<std::size_t>(n)],
                                   input[static_cast<std::size_t>(n)].exact);
    return sum / frames;
  };
  const double tSilhouette = msPerFrame(frames, repeats, silhouettes);
  const double tHull = msPerFrame(frames, repeats, hull);
  const double iou = meanIoU();
  const double tField = msPerFrame(frames, repeats, field);
  const double tMesh = msPerFrame(frames, repeats, mesh);
  const double tChain = msPerFrame(frames, repeats, [&](int n) {
    silhouettes(n);
    hull(n);
    field(n);
    mesh(n);
  });
  print(cameraCount, size, voxels, "silhouette", tSilhouette, -1, host);
  print(cameraCount, size, voxels, "hull", tHull, iou, host);
  print(cameraCount, size, voxels, "distance_field", tField, -1, host);
  print(cameraCount, size, voxels, "mesh", tMesh, -1, host);
  print(cameraCount, size, voxels, "chain", tChain, meanIoU(), host);
  if (baseline) {
    double sum = 0;
    const double tBaseline = msPerFrame(std::min(frames, 3), 1, [&](int n) {
      auto carved = carveVisualHullBaseline(views[static_cast<std::size_t>(n)], spec);
      sum += intersectionOverUnion(*carved, input[static_cast<std::size_t>(n)].exact);
    });
    print(cameraCount, size, voxels, "baseline", tBaseline, sum / (std::min(frames, 3) + 1), host);
  }
}

// The module chain: 5 synthetic captures (their colour rendering included) -> silhouettes ->
// merge -> hull, per frame: the run's wall time, and each kind's compute time.
void runModules(int cameraCount, cv::Size size, int voxels, int iterations,
                const std::string& host) {
  const ModuleChainTimes times = runModuleChain(cameraCount, size, voxels, iterations);
  if (!times.error.empty()) {
    std::fprintf(stderr, "vrflow-bench-camera: %s\n", times.error.c_str());
    return;
  }
  print(cameraCount, size, voxels, "modules_capture", times.captureMs, -1, host);
  print(cameraCount, size, voxels, "modules_silhouette", times.silhouetteMs, -1, host);
  print(cameraCount, size, voxels, "modules_hull", times.hullMs, -1, host);
  print(cameraCount, size, voxels, "modules_wall", times.wallMsPerFrame, -1, host);
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::string host = machine();
  const int frames = quick ? 2 : 10, repeats = quick ? 1 : 3;
  if (quick) {
    runCase(5, {320, 240}, 32, frames, repeats, true, host);
    runModules(5, {320, 240}, 32, 8, host);
    return 0;
  }
  if (argc == 4 && std::strcmp(argv[1], "--case") == 0) {
    runCase(std::atoi(argv[2]), {640, 480}, std::atoi(argv[3]), frames, repeats, false, host);
    return 0;
  }
  runCase(5, {640, 480}, 128, frames, repeats, true, host);
  runModules(5, {640, 480}, 128, 60, host);
  runCase(5, {640, 480}, 64, frames, repeats, true, host);
  runCase(4, {640, 480}, 128, frames, repeats, false, host);
  runCase(3, {640, 480}, 128, frames, repeats, false, host);
  return 0;
}
