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

// The first problem found in the parameters' values (their types and ranges were checked by
// the validator against the manifest; these are the viewer's own rules).
class ParamProblems {
 public:
  explicit ParamProblems(const Module& module) : module_(module) {}

  std::optional<ParamError> error;

  void fail(const char* name, const std::string& what) {
    if (!error) {
      error = ParamError{"module '" + module_.id() + "' (viewer/viewer): parameter '" + name +
                         "' " + what};
    }
  }

 private:
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
  ParamProblems params(module);
  const Parameters& values = module.params();
  viewer::RenderSettings render;
  render.width = static_cast<int>(values.getInt("width"));
  render.height = static_cast<int>(values.getInt("height"));
  render.ground = values.getBool("ground");
  render.groundHeight = values.getFloat("ground-height");
  render.groundHalfSize = values.getFloat("ground-size");
  render.groundTile = values.getFloat("ground-tile");
  render.shadows = values.getBool("shadows");
  render.netLines = values.getBool("net-lines");
  render.supersample = static_cast<int>(values.getInt("supersample"));
  render.pointRadius = values.getFloat("point-radius");
  render.particleSize = static_cast<float>(values.getFloat("particle-size"));
  if (auto tile = viewer::parseTile(values.getString("tile")); tile) {
    render.tile = *tile;
  } else {
    params.fail("tile", tile.error().message);
  }
  const double viewDepth = values.getFloat("view-depth");
  std::optional<msg::Aabb> interestBox;
  if (const auto text = values.getString("interest-box"); !text.empty()) {
    if (auto box = viewer::parseBox(text); box) {
      interestBox = *box;
    } else {
      params.fail("interest-box", box.error().message);
    }
  }
  const int segments = static_cast<int>(values.getInt("segments"));
  const int every = static_cast<int>(values.getInt("every"));
  viewer::Camera camera;
  camera.eye = values.getVec3("eye");
  camera.target = values.getVec3("target");
  camera.up = values.getVec3("up");
  camera.fovYDegrees = values.getFloat("fov");
  viewer::FrameWriterSettings output;
  output.directory = values.getString("output-dir");
  output.prefix = values.getString("prefix");
  output.width = render.width;
  output.height = render.height;
  output.fps = values.getFloat("fps");
  if (auto format = viewer::parseFrameFormat(values.getString("format")); format) {
    output.format = *format;
  } else {
    params.fail("format", "expects png, mp4 or auto, got '" + values.getString("format") + "'");
  }
  if (camera.eye == camera.target) params.fail("eye", "must differ from 'target'");
  if (viewDepth <= camera.nearPlane) {
    params.fail("view-depth", "must be beyond the near plane (" + std::to_string(camera.nearPlane) +
                                  " m), got " + std::to_string(viewDepth));
  }
  std::optional<viewer::CameraPath> path;
  if (const auto file = values.getString("camera-path"); !file.empty()) {
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
