// vrflow-bench-camera: ms per frame of each stage of the camera chain (silhouettes of every
// camera, hierarchical visual hull, signed distance field, mesh) and of the whole chain, on
// synthetic frames of the moving user, in one run: the library's stages on 1 thread and on
// --threads (default: the cores), the same stages as they were before the speed round
// (reference_chain.hpp, stages reference_*), and the straightforward carving (cv::projectPoints
// of every voxel into every mask, stage baseline). One JSON line per stage: {cameras, width,
// height, voxels, stage, code, threads, ms_per_frame, iou, same_bits_as_reference, load,
// machine}. `--quick`: a smoke run; `--case C V`: C cameras, V^3 only; `--no-modules`. The
// stages `modules_*` run the chain as modules (capture, silhouette, hull, user animator) through
// `vrflow run`.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "modules_stage.hpp"
#include "reference_chain.hpp"
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

// The process's CPU time (ms), all its threads: on a loaded machine the wall time measures the
// others' work as well.
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// The best wall and CPU ms per frame of a stage (each the least over the passes).
struct Timing {
  double ms = 1e30;
  double cpuMs = 1e30;
};

Timing msPerFrame(int frames, int repeats, const std::function<void(int)>& work) {
  work(0);  // warm the caches and OpenCV's buffers
  Timing best;
  for (int r = 0; r < repeats; ++r) {
    const double c0 = cpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    for (int n = 0; n < frames; ++n) work(n);
    const auto t1 = std::chrono::steady_clock::now();
    best.cpuMs = std::min(best.cpuMs, (cpuMs() - c0) / frames);
    best.ms =
        std::min(best.ms, std::chrono::duration<double, std::milli>(t1 - t0).count() / frames);
  }
  return best;
}

// Best ms per frame of each of `variants` alternatives: `repeats` passes, each running every
// variant over every frame in turn (after one warm-up frame each).
std::vector<Timing> bestOfAlternating(std::size_t variants, int frames, int repeats,
                                      const std::function<void(std::size_t, int)>& work) {
  for (std::size_t v = 0; v < variants; ++v) work(v, 0);
  std::vector<Timing> best(variants);
  for (int r = 0; r < repeats; ++r)
    for (std::size_t v = 0; v < variants; ++v) {
      const double c0 = cpuMs();
      const auto t0 = std::chrono::steady_clock::now();
      for (int n = 0; n < frames; ++n) work(v, n);
      const auto t1 = std::chrono::steady_clock::now();
      best[v].cpuMs = std::min(best[v].cpuMs, (cpuMs() - c0) / frames);
      best[v].ms =
          std::min(best[v].ms, std::chrono::duration<double, std::milli>(t1 - t0).count() / frames);
    }
  return best;
}

// The one-minute load average when the case started: the machine is shared.
double loadAverage() {
  double load = -1;
  std::ifstream("/proc/loadavg") >> load;
  return load;
}

// One JSON line; `code` is "fast" (the library), "reference" (the stages before the speed round,
// reference_chain.hpp) or "baseline"; `same` whether the fast output equals the reference's bits.
struct Line {
  int cameras;
  cv::Size size;
  int voxels;
  const std::string& host;
  double load;
  double band;  // the fast distance field's band (m); its bits are compared within it

  void print(const std::string& stage, const char* code, int threads, Timing t, double iou,
             int same = -1) const {
    std::printf(
        "{\"cameras\": %d, \"width\": %d, \"height\": %d, \"voxels\": %d, \"stage\": \"%s\", "
        "\"code\": \"%s\", \"threads\": %d, \"ms_per_frame\": %.3f, \"cpu_ms_per_frame\": %s, "
        "\"iou\": %s, "
        "\"same_bits_as_reference\": %s, \"field_band_m\": %.4f, \"load\": %.2f, "
        "\"machine\": \"%s\"}\n",
        cameras, size.width, size.height, voxels, stage.c_str(), code, threads, t.ms,
        t.cpuMs < 0 ? "null" : std::to_string(t.cpuMs).c_str(),
        iou < 0 ? "null" : std::to_string(iou).c_str(),
        same < 0 ? "null" : (same ? "true" : "false"), band, load, host.c_str());
    std::fflush(stdout);
  }
};

// Each stage's output per frame, so that the next stage is timed alone.
struct StageOutputs {
  std::vector<VoxelGrid> hulls;
  std::vector<std::vector<float>> fields;
  std::vector<TriangleMesh> meshes;
};

void runCase(int cameraCount, cv::Size size, int voxels, int frames, int repeats, bool baseline,
             int threads, double reach, const std::string& host) {
  const std::vector<CameraCalibration> cameras = cameraRing(cameraCount, size);
  const GridSpec spec = userVolume(voxels);
  const double band = fieldBandFor(reach, spec);
  const Line line{cameraCount, size, voxels, host, loadAverage(), band};
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
  const auto at = [](auto& vector, int n) -> auto& {
    return vector[static_cast<std::size_t>(n)];
  };
  std::vector<std::vector<MaskView>> views(static_cast<std::size_t>(frames));
  auto silhouettes = [&](int n, int silhouetteThreads) {
    auto& v = at(views, n);
    v.clear();
    auto masks = *extractSilhouettes(extractors, at(input, n).images, silhouetteThreads);
    for (int c = 0; c < cameraCount; ++c) v.push_back({&at(cameras, c), std::move(at(masks, c))});
  };
  std::vector<int> threadCounts{1};
  if (threads > 1) threadCounts.push_back(threads);
  const std::vector<Timing> tSilhouette =
      bestOfAlternating(threadCounts.size(), frames, repeats,
                        [&](std::size_t v, int n) { silhouettes(n, threadCounts[v]); });
  for (std::size_t v = 0; v < threadCounts.size(); ++v)
    line.print("silhouette", "fast", threadCounts[v], tSilhouette[v], -1);
  auto newOutputs = [&] {
    return StageOutputs{std::vector<VoxelGrid>(static_cast<std::size_t>(frames), VoxelGrid(spec)),
                        std::vector<std::vector<float>>(static_cast<std::size_t>(frames)),
                        std::vector<TriangleMesh>(static_cast<std::size_t>(frames))};
  };
  auto meanIoU = [&](const StageOutputs& out) {
    double sum = 0;
    for (int n = 0; n < frames; ++n)
      sum += intersectionOverUnion(at(out.hulls, n), at(input, n).exact);
    return sum / frames;
  };
  // The variants side by side: the stages before the speed round (one thread), then the
  // library's on 1 and on `threads` threads. Each stage is timed in passes that alternate the
  // variants, the best pass kept for each, so a load that changes during the run (the machine is
  // shared) weighs on all of them alike.
  const std::size_t variants = 1 + threadCounts.size();
  std::vector<StageOutputs> out;
  for (std::size_t v = 0; v < variants; ++v) out.push_back(newOutputs());
  auto hull = [&](std::size_t v, int n) {
    if (v == 0) return reference::carveVisualHull(at(views, n), at(out[0].hulls, n));
    (void)carveVisualHull(at(views, n), 0, spec.nz, at(out[v].hulls, n), nullptr,
                          threadCounts[v - 1]);
  };
  // The library's field is exact within the band the interactors read (--reach plus the
  // sampling stencil, fieldBandFor) and the band beyond: its bits are compared with the
  // reference's clamped to the band.
  auto field = [&](std::size_t v, int n) {
    at(out[v].fields, n) =
        v == 0 ? reference::signedDistanceField(at(out[0].hulls, n))
               : signedDistanceFieldInBand(at(out[v].hulls, n), band, threadCounts[v - 1]);
  };
  auto mesh = [&](std::size_t v, int n) {
    at(out[v].meshes, n) = v == 0 ? reference::meshHull(at(out[0].hulls, n), at(out[0].fields, n))
                                  : meshHull(at(out[v].hulls, n), at(out[v].fields, n));
  };
  // The target's chain: silhouettes to the hull and its distance field; `chain` adds the mesh.
  auto hullAndField = [&](std::size_t v, int n) {
    silhouettes(n, v == 0 ? 1 : threadCounts[v - 1]);
    hull(v, n);
    field(v, n);
  };
  auto chain = [&](std::size_t v, int n) {
    hullAndField(v, n);
    mesh(v, n);
  };
  const std::vector<Timing> tHull = bestOfAlternating(variants, frames, repeats, hull);
  const std::vector<Timing> tField = bestOfAlternating(variants, frames, repeats, field);
  const std::vector<Timing> tMesh = bestOfAlternating(variants, frames, repeats, mesh);
  // This round's before: the library's field over the whole grid (signedDistanceField).
  std::vector<float> wholeField;
  const std::vector<Timing> tWholeField =
      bestOfAlternating(variants - 1, frames, repeats, [&](std::size_t v, int n) {
        wholeField = signedDistanceField(at(out[v + 1].hulls, n), threadCounts[v]);
      });
  const std::vector<Timing> tHullField = bestOfAlternating(variants, frames, repeats, hullAndField);
  const std::vector<Timing> tChain = bestOfAlternating(variants, frames, repeats, chain);
  line.print("reference_hull", "reference", 1, tHull[0], meanIoU(out[0]));
  line.print("reference_distance_field", "reference", 1, tField[0], -1);
  line.print("reference_mesh", "reference", 1, tMesh[0], -1);
  line.print("reference_chain_hull_field", "reference", 1, tHullField[0], meanIoU(out[0]));
  line.print("reference_chain", "reference", 1, tChain[0], meanIoU(out[0]));
  const StageOutputs& before = out[0];
  for (std::size_t v = 1; v < variants; ++v) {
    const StageOutputs& after = out[v];
    bool sameHulls = true, sameFields = true, sameMeshes = true;
    for (int n = 0; n < frames; ++n) {
      sameHulls = sameHulls && at(after.hulls, n).occupied == at(before.hulls, n).occupied;
      std::vector<float> clamped = at(before.fields, n);
      for (float& d : clamped) d = std::min(d, static_cast<float>(band));
      sameFields = sameFields && at(after.fields, n).size() == clamped.size() &&
                   std::memcmp(at(after.fields, n).data(), clamped.data(),
                               clamped.size() * sizeof(float)) == 0;
      sameMeshes = sameMeshes && at(after.meshes, n).vertices == at(before.meshes, n).vertices &&
                   at(after.meshes, n).triangles == at(before.meshes, n).triangles;
    }
    const int t = threadCounts[v - 1];
    line.print("hull", "fast", t, tHull[v], meanIoU(after), sameHulls);
    line.print("whole_distance_field", "fast", t, tWholeField[v - 1], -1);
    line.print("distance_field", "fast", t, tField[v], -1, sameFields);
    line.print("mesh", "fast", t, tMesh[v], -1, sameMeshes);
    line.print("chain_hull_field", "fast", t, tHullField[v], meanIoU(after),
               sameHulls && sameFields);
    line.print("chain", "fast", t, tChain[v], meanIoU(after),
               sameHulls && sameFields && sameMeshes);
  }
  if (baseline) {
    double sum = 0;
    const int baselineFrames = std::min(frames, 3);
    const Timing tBaseline = msPerFrame(baselineFrames, 1, [&](int n) {
      auto carved = carveVisualHullBaseline(at(views, n), spec);
      sum += intersectionOverUnion(*carved, at(input, n).exact);
    });
    line.print("baseline", "baseline", 1, tBaseline, sum / (baselineFrames + 1));
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
  const Line line{cameraCount, size, voxels, host, loadAverage(), -1};
  line.print("modules_capture", "fast", 1, {times.captureMs, -1}, -1);
  line.print("modules_silhouette", "fast", 1, {times.silhouetteMs, -1}, -1);
  line.print("modules_hull", "fast", 1, {times.hullMs, -1}, -1);
  line.print("modules_animator", "fast", 1, {times.animatorMs, -1}, -1);
  line.print("modules_wall", "fast", 1, {times.wallMsPerFrame, -1}, -1);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string host = machine();
  bool quick = false, modules = true;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  int onlyCameras = 0, onlyVoxels = 0;
  // The example's largest reach into the user's field: a 0.15 m ball's centre plus the rigid
  // interactor's 0.04 m speculative distance.
  double reach = 0.19;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--no-modules") {
      modules = false;
    } else if (arg == "--threads" && a + 1 < argc) {
      threads = std::atoi(argv[++a]);
    } else if (arg == "--reach" && a + 1 < argc) {
      reach = std::atof(argv[++a]);
    } else if (arg == "--case" && a + 2 < argc) {
      onlyCameras = std::atoi(argv[++a]);
      onlyVoxels = std::atoi(argv[++a]);
    } else {
      std::fprintf(
          stderr,
          "usage: vrflow-bench-camera [--quick] [--no-modules] [--threads N] "
          "[--reach METRES] [--case CAMERAS VOXELS]\n(unknown or incomplete argument '%s')\n",
          arg.c_str());
      return 2;
    }
  }
  if (threads < 1 || !(reach >= 0 && reach < 100) ||
      (onlyCameras != 0 && (onlyCameras < 1 || onlyVoxels < 2))) {
    std::fprintf(stderr,
                 "vrflow-bench-camera: --threads must be >= 1, --reach in [0, 100) m, --case "
                 "needs >= 1 camera and >= 2 voxels\n");
    return 2;
  }
  const int frames = quick ? 2 : 10, repeats = quick ? 1 : 5;
  if (quick) {
    runCase(5, {320, 240}, 32, frames, repeats, true, threads, reach, host);
    if (modules) runModules(5, {320, 240}, 32, 8, host);
    return 0;
  }
  if (onlyCameras != 0) {
    runCase(onlyCameras, {640, 480}, onlyVoxels, frames, repeats, true, threads, reach, host);
    return 0;
  }
  runCase(5, {640, 480}, 128, frames, repeats, true, threads, reach, host);
  if (modules) runModules(5, {640, 480}, 128, 60, host);
  runCase(5, {640, 480}, 64, frames, repeats, true, threads, reach, host);
  runCase(4, {640, 480}, 128, frames, repeats, false, threads, reach, host);
  runCase(3, {640, 480}, 128, frames, repeats, false, threads, reach, host);
  return 0;
}
