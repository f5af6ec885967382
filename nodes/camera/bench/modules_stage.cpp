#include "modules_stage.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "vrflow/camera/synthetic_scene.hpp"

namespace vrflow::camera {

namespace {

constexpr int kEmptyFrames = 5;

std::string param(const std::string& name, const std::string& value) {
  return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
}

// The user's reference pose, held: the keyframe file of the synthetic captures.
std::string standingKeys() {
  std::ostringstream out;
  const UserPose pose = standingPose();
  for (std::size_t i = 0; i < pose.size(); ++i)
    out << "0 " << kUserJoints[i] << ' ' << pose[i][0] << ' ' << pose[i][1] << ' ' << pose[i][2]
        << '\n';
  return out.str();
}

std::string chainApplication(const std::filesystem::path& dir, int cameras, int voxels) {
  std::string modules, connections, calibrations;
  for (int n = 0; n < cameras; ++n) {
    const std::string i = std::to_string(n);
    const std::string calibration = (dir / ("cam" + i + ".yml")).string();
    calibrations += (n ? " " : "") + calibration;
    modules += "    <module id=\"cam" + i +
               "\" package=\"camera\" type=\"capture\" host=\"local\">\n" +
               param("source", "synthetic") + param("calibration", calibration) +
               param("keyframes", (dir / "user.keys").string()) +
               param("empty-frames", std::to_string(kEmptyFrames)) + param("room-seed", i) +
               param("noise", "4") + "    </module>\n";
    modules += "    <module id=\"sil" + i +
               "\" package=\"camera\" type=\"silhouette\" host=\"local\">\n" +
               param("calibration", calibration) +
               param("background-frames", std::to_string(kEmptyFrames)) + "    </module>\n";
    connections += "    <connection from=\"cam" + i + ".image\" to=\"sil" + i + ".image\"/>\n";
    connections += "    <connection from=\"sil" + i + ".mask\" to=\"masks.in" + i + "\"/>\n";
  }
  modules += "    <module id=\"hull\" package=\"camera\" type=\"hull\" host=\"local\">\n" +
             param("calibrations", calibrations) + param("cells", std::to_string(voxels)) +
             "    </module>\n";
  modules +=
      "    <module id=\"animator\" package=\"camera\" type=\"user-animator\" "
      "host=\"local\"/>\n";
  connections += "    <connection from=\"masks.out\" to=\"hull.masks\"/>\n";
  connections += "    <connection from=\"hull.hull\" to=\"animator.hull\"/>\n";
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"bench-camera\" "
         "version=\"1\">\n  <hosts>\n    <host id=\"local\" address=\"127.0.0.1\"/>\n  </hosts>\n"
         "  <modules>\n" +
         modules + "  </modules>\n  <filters>\n    <filter id=\"masks\" type=\"merge\">\n" +
         param("inputs", std::to_string(cameras)) +
         "    </filter>\n  </filters>\n  <connections>\n" + connections +
         "  </connections>\n</application>\n";
}

}  // namespace

ModuleChainTimes runModuleChain(int cameras, cv::Size size, int voxels, int iterations) {
  ModuleChainTimes times;
  std::string pattern = (std::filesystem::temp_directory_path() / "vrflow-bench-camera-XXXXXX");
  if (!mkdtemp(pattern.data())) return {0, 0, 0, 0, 0, "cannot create a temporary folder"};
  const std::filesystem::path dir = pattern;
  const auto rig = cameraRing(cameras, size);
  for (int n = 0; n < cameras; ++n)
    if (!saveCalibration(rig[static_cast<std::size_t>(n)],
                         (dir / ("cam" + std::to_string(n) + ".yml")).string()))
      return {0, 0, 0, 0, 0, "cannot write a calibration in " + dir.string()};
  std::ofstream(dir / "user.keys") << standingKeys();
  std::ofstream(dir / "chain.xml") << chainApplication(dir, cameras, voxels);
  const auto bin = std::filesystem::read_symlink("/proc/self/exe").parent_path();
  const std::string command = (bin / "vrflow").string() + " run " + (dir / "chain.xml").string() +
                              " --iterations " + std::to_string(iterations) + " --report " +
                              (dir / "report.json").string() + " --no-progress --log-dir " +
                              dir.string() + " > " + (dir / "run.txt").string() + " 2>&1";
  if (std::system(command.c_str()) != 0) {
    times.error = "the module chain failed: see " + (dir / "run.txt").string();
    return times;
  }
  const auto report = nlohmann::json::parse(std::ifstream(dir / "report.json"));
  times.wallMsPerFrame = report["timing"]["wall_s"].get<double>() * 1000 / iterations;
  for (const auto& module : report["modules"]) {
    const std::string id = module["id"];
    const auto& timing = module["timing"];
    const double computeMs = timing["compute_s"].get<double>() * 1000 / iterations;
    if (id.rfind("cam", 0) == 0)
      times.captureMs = std::max(times.captureMs, computeMs);
    else if (id.rfind("sil", 0) == 0)
      times.silhouetteMs = std::max(times.silhouetteMs, computeMs);
    else if (id == "hull")
      times.hullMs = computeMs;
    else if (id == "animator")
      times.animatorMs = computeMs;
  }
  std::filesystem::remove_all(dir);
  return times;
}

}  // namespace vrflow::camera
