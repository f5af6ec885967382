// vrflow-bench-camera-latency: issue 21's capture-to-interactor latency in frames, measured in a
// real run of the camera network. It records (`vrflow record`) the rigid and mass-spring
// interactors' outputs and the user animator's objects of examples/camera_user at the CI size
// (5 synthetic cameras, 5 silhouettes, a merge, the hull in 2 slabs, the user animator, the
// paper's scene) and prints one JSON line per interactor:
// {"stage": "latency", "connection", "frames", "frames_min", "messages", "first_use_iteration",
//  "iterations", "machine"} (frames: the largest interactor iteration minus the capture iteration
// of the user it used), then the same for the user animator's output ("stage": "animator").
//   vrflow-bench-camera-latency [ITERATIONS (40)]
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "vrflow/camera/capture_latency.hpp"
#include "vrflow/camera/capture_stamps.hpp"

namespace {

std::string here() {
  return std::filesystem::canonical("/proc/self/exe").parent_path().string();
}

std::string machine() {
  char name[256] = {};
  gethostname(name, sizeof name - 1);
  return name;
}

void print(const char* stage, const std::string& connection,
           const vrflow::camera::LatencyFrames& frames, int iterations) {
  std::printf(
      "{\"stage\": \"%s\", \"connection\": \"%s\", \"frames\": %lld, \"frames_min\": %lld, "
      "\"messages\": %llu, \"first_use_iteration\": %lld, \"iterations\": %d, \"machine\": "
      "\"%s\"}\n",
      stage, connection.c_str(), static_cast<long long>(frames.max),
      static_cast<long long>(frames.min), static_cast<unsigned long long>(frames.messages),
      static_cast<long long>(frames.firstUseIteration), iterations, machine().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::atoi(argv[1]) : 40;
  if (iterations < 1) {
    std::fprintf(stderr, "vrflow-bench-camera-latency: ITERATIONS must be a positive integer\n");
    return 2;
  }
  const auto folder = std::filesystem::temp_directory_path() /
                      ("vrflow-bench-camera-latency-" + std::to_string(getpid()));
  std::filesystem::create_directories(folder);
  const std::string recording = (folder / "latency.vrrec").string();
  const std::string command =
      "cd '" + folder.string() + "' && '" + here() +
      "/vrflow' record '" VRFLOW_SOURCE_DIR
      "/examples/camera_user/camera_user.xml' --connections "
      "contacts.forces,net-contacts.forces,user.objects -o '" +
      recording + "' -n " + std::to_string(iterations) +
      " --no-progress --set hull.cells=40 --set water.nx=16 --set water.ny=24 --set water.nz=16 "
      "--set water.cell-size=0.125 --set view.every=1000 > run.log 2>&1";
  if (std::system(command.c_str()) != 0) {
    std::fprintf(stderr, "vrflow-bench-camera-latency: the run failed; see %s/run.log\n",
                 folder.c_str());
    return 1;
  }
  const auto used =
      vrflow::camera::latencyFrames(recording, vrflow::camera::kUsedCaptureIterationStamp);
  const auto made =
      vrflow::camera::latencyFrames(recording, vrflow::camera::kCaptureIterationStamp);
  if (!used || !made) {
    std::fprintf(stderr, "vrflow-bench-camera-latency: %s\n",
                 (!used ? used.error() : made.error()).message.c_str());
    return 1;
  }
  for (const auto& [connection, frames] : *used) print("latency", connection, frames, iterations);
  for (const auto& [connection, frames] : *made) print("animator", connection, frames, iterations);
  std::filesystem::remove_all(folder);
  return used->size() == 2 ? 0 : 1;
}
