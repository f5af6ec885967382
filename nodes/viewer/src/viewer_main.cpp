// viewer/viewer: renders the objects it receives with OSMesa (or into a window on an X display)
// into PNG frames or an MP4, the whole view or one tile of a wall. It only reads: its outputs
// are the implicit endIt, `interest` (its volume of interest, for a `route` filter), `events`
// (its window's pointer and keys) and `ready` (the swap-lock), so it cannot change what the
// simulation computes.
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include "swap_lock.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/viewer/frame_writer.hpp"
#include "vrflow/viewer/renderer.hpp"
#include "vrflow/viewer/view_volume.hpp"
#include "vrflow/viewer/wall.hpp"
#include "vrflow/viewer/window.hpp"

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
  auto& events = module.addOutput("events");
  auto& ready = module.addOutput("ready");
  auto& release = module.addInput("swap");
  auto& head = module.addInput("head");
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
  const bool writeFrames = values.getString("format") != "none";
  if (!writeFrames) {
    output.format = viewer::FrameFormat::Png;  // unused
  } else if (auto format = viewer::parseFrameFormat(values.getString("format")); format) {
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
  // A tile of a wall file: its pixels, blend mask and head-coupled view replace the viewer's own
  // size, tile and camera; `window` 'wall' takes its display and window from the file.
  std::optional<viewer::Wall> wall;
  const viewer::WallTile* wallTile = nullptr;
  std::string place = values.getString("window");
  std::string display = values.getString("display");
  if (const auto file = values.getString("wall"); !file.empty()) {
    auto loaded = viewer::loadWall(file);
    if (!loaded) {
      params.fail("wall", loaded.error().message);
    } else {
      wall = std::move(*loaded);
      wallTile = wall->find(values.getString("wall-tile"));
      if (!wallTile) {
        params.fail("wall-tile", "names no tile of wall file '" + file + "': '" +
                                     values.getString("wall-tile") + "'");
      }
    }
    if (values.getString("tile") != "0 0 1 1") params.fail("tile", "conflicts with 'wall'");
    if (!values.getString("camera-path").empty()) {
      params.fail("camera-path", "conflicts with 'wall' (the wall's eye or 'head' moves it)");
    }
  } else if (!values.getString("wall-tile").empty()) {
    params.fail("wall-tile", "needs 'wall'");
  }
  if (wallTile) {
    render.width = output.width = wall->pixelsX;
    render.height = output.height = wall->pixelsY;
    render.blendMask = viewer::blendMask(*wall, wallTile->col, wallTile->row);
    if (place == "wall") {
      place = wallTile->window;
      if (display.empty()) display = wallTile->display;
    }
  } else if (place == "wall") {
    params.fail("window", "is 'wall' but no 'wall' file is given");
  }
  std::optional<viewer::WindowSettings> onScreen;
  if (!place.empty()) {
    onScreen = viewer::WindowSettings{};
    onScreen->display = display;
    onScreen->width = render.width;
    onScreen->height = render.height;
    onScreen->title = "vrflow " + module.id();
    std::istringstream in(place);
    std::string extra;
    if (place == "fullscreen") {
      onScreen->fullScreen = true;
    } else if (!(in >> onScreen->x >> onScreen->y) || (in >> extra)) {
      params.fail("window", "expects 'fullscreen' or the top-left corner 'X Y' (pixels), got '" +
                                place + "'");
    }
    if (render.supersample != 1) params.fail("supersample", "must be 1 on screen ('window' set)");
  } else if (!display.empty()) {
    params.fail("display", "needs 'window' ('fullscreen' or 'X Y') to open a window on it");
  }
  if (release.connected() != ready.connected()) {
    params.fail("swap-log",
                "the swap-lock needs both 'ready' and 'swap' connected (through "
                "merge and broadcast filters), not one of them");
  }
  if (params.error) {
    std::fprintf(stderr, "vrflow-viewer: %s\n", params.error->message.c_str());
    return 2;
  }
  if (!path) path = viewer::CameraPath(camera);

  const std::string prefix = "vrflow-viewer: module '" + module.id() + "': ";
  const auto fail = [&prefix](const Error& error) {
    std::fprintf(stderr, "%s%s\n", prefix.c_str(), error.message.c_str());
    return 2;
  };
  std::optional<viewer::Window> window;
  if (onScreen) {
    auto opened = viewer::Window::open(*onScreen);
    if (!opened) return fail(opened.error());
    window = std::move(*opened);
  }
  auto renderer =
      window ? viewer::Renderer::create(render, *window) : viewer::Renderer::create(render);
  if (!renderer) return fail(renderer.error());
  std::optional<viewer::FrameWriter> writer;
  if (writeFrames) {
    auto opened = viewer::FrameWriter::open(output);
    if (!opened) return fail(opened.error());
    writer = std::move(*opened);
  }
  // Swap at an absolute time (the latest tile's ready + margin) instead of at the release.
  const auto swapMarginNs = static_cast<std::int64_t>(values.getFloat("swap-margin") * 1e6);
  auto swapLog = viewer::SwapLog::open(values.getString("swap-log"));
  if (!swapLog) return fail(swapLog.error());
  const auto& t = render.tile;
  const std::string tileText =
      wallTile ? ", tile '" + wallTile->id + "' of wall '" + values.getString("wall") + "'"
      : t == viewer::Tile{} ? std::string()
                            : ", tile " + std::to_string(t.col) + " " + std::to_string(t.row) +
                                  " of " + std::to_string(t.cols) + "x" + std::to_string(t.rows);
  const std::string where =
      window ? "a window on " + std::string(std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "?") +
                   (writer ? " and " + writer->description() : std::string())
             : (writer ? writer->description() : std::string("nothing"));
  std::fprintf(stderr, "%sdrawing into %s, %dx%d%s, every %d iteration(s), with %s%s\n",
               prefix.c_str(), where.c_str(), render.width, render.height, tileText.c_str(), every,
               renderer->description().c_str(), release.connected() ? ", swap-locked" : "");

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
  const std::uint64_t eventSource = module.newId();
  // The head: the first point object (by id) of the `head` input, as last seen.
  viewer::SceneCache heads(4, [](const std::string&) {});
  std::optional<viewer::TileView> wallView;
  bool headRefused = false;
  std::optional<std::uint64_t> readied;  // the iteration whose `ready` went out last
  bool drawn = false;                    // that iteration's frame waits in the back buffer
  std::uint64_t shown = 0;
  while (module.wait()) {
    if (release.connected()) {
      // Every tile has drawn the frame this release names: show it now.
      auto frame = viewer::releasedFrame(module.get(release).view().stamps());
      if (frame && *frame != readied) {
        frame = makeError("the swap release names frame " +
                          (*frame ? std::to_string(**frame) : "none") + " but this tile is at " +
                          (readied ? std::to_string(*readied) : "none"));
      }
      if (!frame) {
        status = fail(frame.error());
        break;
      }
      if (drawn) {
        const auto& stamps = module.get(release).view().stamps();
        if (const auto at = viewer::swapTime(stamps, swapMarginNs); at && swapMarginNs > 0) {
          viewer::sleepUntilRealtime(*at);
        }
        if (window) window->swap();
        swapLog->shown(*readied);
        ++shown;
        drawn = false;
      }
    }
    if (head.connected() && module.get(head).valid()) heads.apply(module.get(head).view());
    if (wallTile) {
      msg::Vec3 eye = wall->eye;
      for (const auto& [id, object] : heads.objects()) {
        if (object.kind != viewer::ObjectKind::Point) continue;
        eye = object.position;
        break;
      }
      auto view = viewer::tileView(*wall, wallTile->col, wallTile->row, eye);
      if (view) {
        wallView = *view;
        headRefused = false;
      } else if (!headRefused) {
        // Logged once per stretch: the tile keeps the last view it could make.
        std::fprintf(stderr, "%shead position refused (%s)%s\n", prefix.c_str(),
                     view.error().message.c_str(), wallView ? ": keeping the last view" : "");
        headRefused = true;
      }
      if (!wallView) {
        status = fail(view.error());
        break;
      }
    }
    const auto cam = wallView ? wallView->camera : path->at(module.iteration());
    const auto frustum = wallView
                             ? wallView->frustum
                             : viewer::tileFrustum(cam, render.tile, render.width, render.height);
    if (window) {
      // The window's events, each pointer event with its world ray through this tile's view.
      auto happened = window->poll();
      if (events.connected() && !happened.empty()) {
        auto out = module.newMessage(256 + 160 * happened.size());
        for (auto& event : happened) {
          if (auto* pointer = std::get_if<msg::PointerEvent>(&event)) {
            const auto ray = viewer::pointerRay(cam, frustum, render.width, render.height,
                                                pointer->x, pointer->y);
            pointer->rayOrigin = ray.origin;
            pointer->rayDirection = ray.direction;
            msg::addPointerEvent(out.builder(), eventSource, *pointer);
          } else {
            msg::addKeyEvent(out.builder(), eventSource, std::get<msg::KeyEvent>(event));
          }
        }
        if (!module.put(events, std::move(out))) break;
      }
      if (window->closeRequested()) {
        std::fprintf(stderr, "%sthe window was closed: ending\n", prefix.c_str());
        break;
      }
    }
    const Message& message = module.get(objects);
    if (message.valid()) scene.apply(message.view());
    if (interest.connected()) {
      // At iteration 0, then whenever the camera moves the tile's volume: the box around its
      // frustum from the near plane to view-depth, within interest-box ("none" when empty).
      const auto volume = viewer::viewVolume(cam, frustum, viewDepth, interestBox);
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
    if (module.iteration() % static_cast<std::uint64_t>(every) == 0) {
      auto image = renderer->render(scene, cam, frustum, interest.connected() ? &within : nullptr);
      Status written = !image ? Status(image.error()) : writer ? writer->write(*image) : Status();
      if (!written) {
        std::fprintf(stderr, "%s%s\n", prefix.c_str(), written.error().message.c_str());
        status = 1;
        break;
      }
      if (release.connected()) {
        drawn = true;
      } else if (window) {
        window->swap();
      }
    }
    if (ready.connected()) {
      // Every iteration, drawn or not (`every`), so the barrier never waits on this tile.
      auto out = module.newMessage();
      viewer::stampReady(out.builder(), module.iteration(),
                         swapMarginNs > 0 ? std::optional(viewer::realtimeNs()) : std::nullopt);
      if (!module.put(ready, std::move(out))) break;
      readied = module.iteration();
    }
  }
  if (writer) {
    if (auto closed = writer->close(); !closed) {
      std::fprintf(stderr, "%s%s\n", prefix.c_str(), closed.error().message.c_str());
      status = 1;
    }
  }
  std::fprintf(stderr,
               "%s%d frame(s) written, %llu swap-locked frame(s) shown; %llu shape "
               "resource(s) rejected\n",
               prefix.c_str(), writer ? writer->frames() : 0,
               static_cast<unsigned long long>(shown),
               static_cast<unsigned long long>(scene.stats().rejectedShapes));
  return status != 0 ? status : module.exitStatus();
}
