// viewer/viewer: renders the objects it receives with OSMesa into PNG frames or an MP4, the whole
// view or one tile of a wall. It only reads: its outputs are the implicit endIt and `interest`
// (its volume of interest, for a `route` filter), so it cannot change what the simulation
// computes.
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/viewer/frame_writer.hpp"
#include "vrflow/viewer/renderer.hpp"
#include "vrflow/viewer/view_volume.hpp"

namespace {

using namespace vrflow;

// A parameter that does not make sense: the module and parameter are named in the message.
struct ParamError {
  std::string message;
};

class Params {
 public:
  explicit Params(const Module& module) : module_(module) {}

  std::optional<ParamError> error;

  double number(const char* name, double fallback, double min, double max) {
    const std::string text = module_.param(name, "");
    if (text.empty()) return fallback;
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !(value >= min && value <= max)) {
      fail(name, "expects a number in [" + num(min) + ", " + num(max) + "], got '" + text + "'");
      return fallback;
    }
    return value;
  }
  int integer(const char* name, int fallback, int min, int max) {
    const double value = number(name, fallback, min, max);
    if (value != static_cast<double>(static_cast<int>(value))) {
      fail(name, "expects an integer, got '" + module_.param(name, "") + "'");
      return fallback;
    }
    return static_cast<int>(value);
  }
  bool boolean(const char* name, bool fallback) {
    const std::string text = module_.param(name, "");
    if (text.empty()) return fallback;
    if (text == "true" || text == "1") return true;
    if (text == "false" || text == "0") return false;
    fail(name, "expects true, false, 1 or 0, got '" + text + "'");
    return fallback;
  }
  msg::Vec3 vec3(const char* name, const msg::Vec3& fallback) {
    std::string text = module_.param(name, "");
    if (text.empty()) return fallback;
    for (char& c : text) {
      if (c == ',') c = ' ';
    }
    std::istringstream in(text);
    msg::Vec3 v{};
    std::string extra;
    if (!(in >> v[0] >> v[1] >> v[2]) || (in >> extra) || !std::isfinite(v[0]) ||
        !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      fail(name, "expects three finite numbers, got '" + module_.param(name, "") + "'");
      return fallback;
    }
    return v;
  }
  std::string text(const char* name, const char* fallback) { return module_.param(name, fallback); }
  void fail(const char* name, const std::string& what) {
    if (!error) {
      error = ParamError{"module '" + module_.id() + "' (viewer/viewer): parameter '" + name +
                         "' " + what};
    }
  }

 private:
  static std::string num(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
  }
  const Module& module_;
};

}  // namespace

int main() {
  std::signal(SIGPIPE, SIG_IGN);  // a dead ffmpeg shows as a failed write, not a killed viewer
  // Mesa's llvmpipe starts a thread per core unless told otherwise; the viewer shares the host
  // with the solvers, so it draws on one thread unless the user's environment says otherwise.
  setenv("LP_NUM_THREADS", "1", 0);

  Module module;
  auto& objects = module.addInput("objects");
  auto& interest = module.addOutput("interest");
  if (!initOrReport(module, "vrflow-viewer")) return 2;
  Params params(module);
  viewer::RenderSettings render;
  render.width = params.integer("width", 960, 16, 8192);
  render.height = params.integer("height", 540, 16, 8192);
  render.ground = params.boolean("ground", true);
  render.groundHeight = params.number("ground-height", 0.0, -1e6, 1e6);
  render.groundHalfSize = params.number("ground-size", 20.0, 0.01, 1e4);
  render.groundTile = params.number("ground-tile", 1.0, 0.001, 1e4);
  render.shadows = params.boolean("shadows", true);
  render.netLines = params.boolean("net-lines", true);
  render.supersample = params.integer("supersample", 2, 1, 4);
  render.pointRadius = params.number("point-radius", 0.08, 1e-6, 1e6);
  render.particleSize = static_cast<float>(params.number("particle-size", 3.0, 1.0, 64.0));
  if (auto tile = viewer::parseTile(params.text("tile", "0 0 1 1")); tile) {
    render.tile = *tile;
  } else {
    params.fail("tile", tile.error().message);
  }
  const double viewDepth = params.number("view-depth", 20.0, 1e-3, 1e6);
  std::optional<msg::Aabb> interestBox;
  if (const auto text = params.text("interest-box", ""); !text.empty()) {
    if (auto box = viewer::parseBox(text); box) {
      interestBox = *box;
    } else {
      params.fail("interest-box", box.error().message);
    }
  }
  const int segments = params.integer("segments", 24, 4, 256);
  const int every = params.integer("every", 1, 1, 1000000);
  viewer::Camera camera;
  camera.eye = params.vec3("eye", camera.eye);
  camera.target = params.vec3("target", camera.target);
  camera.up = params.vec3("up", camera.up);
  camera.fovYDegrees = params.number("fov", 45.0, 1.0, 170.0);
  viewer::FrameWriterSettings output;
  output.directory = params.text("output-dir", "frames");
  output.prefix = params.text("prefix", "frame");
  output.width = render.width;
  output.height = render.height;
  output.fps = params.number("fps", 30.0, 0.1, 1000.0);
  if (auto format = viewer::parseFrameFormat(params.text("format", "auto")); format) {
    output.format = *format;
  } else {
    params.fail("format", "expects png, mp4 or auto, got '" + params.text("format", "") + "'");
  }
  if (camera.eye == camera.target) params.fail("eye", "must differ from 'target'");
  if (viewDepth <= camera.nearPlane) {
    params.fail("view-depth", "must be beyond the near plane (" + std::to_string(camera.nearPlane) +
                                  " m), got " + std::to_string(viewDepth));
  }
  std::optional<viewer::CameraPath> path;
  if (const auto file = params.text("camera-path", ""); !file.empty()) {
    auto loaded = viewer::CameraPath::load(file, camera);
    if (!loaded) {
      params.fail("camera-path", loaded.error().message);
    } else {
      path = std::move(*loaded);
    }
  }
  if (params.error) {
    std::fprintf(stderr, "vrflow-viewer: %s\n", params.error->message.c_str());
    return 2;
  }
  if (!path) path = viewer::CameraPath(camera);

  auto renderer = viewer::Renderer::create(render);
  if (!renderer) {
    std::fprintf(stderr, "vrflow-viewer: module '%s': %s\n", module.id().c_str(),
                 renderer.error().message.c_str());
    return 2;
  }
  auto writer = viewer::FrameWriter::open(output);
  if (!writer) {
    std::fprintf(stderr, "vrflow-viewer: module '%s': %s\n", module.id().c_str(),
                 writer.error().message.c_str());
    return 2;
  }
  const std::string prefix = "vrflow-viewer: module '" + module.id() + "': ";
  const auto& t = render.tile;
  const std::string tileText =
      t == viewer::Tile{} ? std::string()
                          : ", tile " + std::to_string(t.col) + " " + std::to_string(t.row) +
                                " of " + std::to_string(t.cols) + "x" + std::to_string(t.rows);
  std::fprintf(stderr, "%swriting %s, %dx%d%s, every %d iteration(s); drawing with %s\n",
               prefix.c_str(), writer->description().c_str(), render.width, render.height,
               tileText.c_str(), every, renderer->description().c_str());

  viewer::SceneCache scene(segments, [&prefix](const std::string& line) {
    std::fprintf(stderr, "%s%s\n", prefix.c_str(), line.c_str());
  });
  // The volume of interest last published ("": none yet), and the box a routed viewer draws
  // within: the route stops updating objects that leave the volume, so their last state is
  // stale (an empty box for "none").
  std::string published;
  const double inf = std::numeric_limits<double>::infinity();
  msg::Aabb within{{inf, inf, inf}, {-inf, -inf, -inf}};
  int status = 0;
  while (module.wait()) {
    const Message& message = module.get(objects);
    if (message.valid()) scene.apply(message.view());
    if (interest.connected()) {
      // At iteration 0, then whenever the camera moves the tile's volume: the box around its
      // frustum from the near plane to view-depth, within interest-box ("none" when empty).
      const auto cam = path->at(module.iteration());
      const auto volume = viewer::viewVolume(
          cam, viewer::tileFrustum(cam, render.tile, render.width, render.height), viewDepth,
          interestBox);
      const std::string text = volume ? viewer::formatBox(*volume) : "none";
      within = volume ? *volume : msg::Aabb{{inf, inf, inf}, {-inf, -inf, -inf}};
      if (text != published) {
        auto out = module.newMessage();
        out.builder().setStampsOnly(true);
        out.builder().addStringStamp("interest", text);
        if (!module.put(interest, std::move(out))) break;
        published = text;
      }
    }
    if (module.iteration() % static_cast<std::uint64_t>(every) != 0) continue;
    auto image = renderer->render(scene, path->at(module.iteration()),
                                  interest.connected() ? &within : nullptr);
    Status written = image ? writer->write(*image) : Status(image.error());
    if (!written) {
      std::fprintf(stderr, "%s%s\n", prefix.c_str(), written.error().message.c_str());
      status = 1;
      break;
    }
  }
  if (auto closed = writer->close(); !closed) {
    std::fprintf(stderr, "%s%s\n", prefix.c_str(), closed.error().message.c_str());
    status = 1;
  }
  std::fprintf(stderr, "%s%d frame(s) written; %llu shape resource(s) rejected\n", prefix.c_str(),
               writer->frames(), static_cast<unsigned long long>(scene.stats().rejectedShapes));
  return status != 0 ? status : module.exitStatus();
}
