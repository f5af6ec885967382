// vrflow-wall-mosaic: the wall recorder. Joins the PNG frames that the tiles of a wall wrote
// (DIR/<tile id>_NNNNNN.png, the viewers' `prefix` being their tile's id) into one picture per
// iteration, where each tile sits on the wall, as PNG frames or an MP4.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "vrflow/viewer/frame_writer.hpp"
#include "vrflow/viewer/mosaic.hpp"

namespace {

namespace fs = std::filesystem;
using namespace vrflow;

int fail(const std::string& message) {
  std::fprintf(stderr, "vrflow-wall-mosaic: %s\n", message.c_str());
  return 2;
}

// The frame numbers of `prefix`_NNNNNN.png in `dir`.
std::set<int> framesOf(const std::string& dir, const std::string& prefix) {
  std::set<int> frames;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename();
    if (name.size() != prefix.size() + 11 || name.rfind(prefix + "_", 0) != 0 ||
        name.substr(name.size() - 4) != ".png") {
      continue;
    }
    const std::string digits = name.substr(prefix.size() + 1, 6);
    if (digits.find_first_not_of("0123456789") == std::string::npos) {
      frames.insert(std::stoi(digits));
    }
  }
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Joins the PNG frames of a wall's tiles (DIR/<tile id>_NNNNNN.png) into one "
      "picture of the whole wall per frame."};
  std::string wallFile, dir, out = "mosaic", prefix = "wall", format = "png";
  double fps = 30;
  app.add_option("wall", wallFile, "The wall description (docs/wall.md)")->required();
  app.add_option("frames", dir, "Folder of the tiles' frames")->required();
  app.add_option("--out", out, "Folder for the mosaic")->capture_default_str();
  app.add_option("--prefix", prefix, "PREFIX_NNNNNN.png or PREFIX.mp4")->capture_default_str();
  app.add_option("--format", format, "png, mp4 or auto")->capture_default_str();
  app.add_option("--fps", fps, "Frame rate of the MP4")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  auto wall = viewer::loadWall(wallFile);
  if (!wall) return fail(wall.error().message);
  auto frameFormat = viewer::parseFrameFormat(format);
  if (!frameFormat) return fail("--format expects png, mp4 or auto, got '" + format + "'");
  if (!fs::is_directory(dir)) return fail("no folder '" + dir + "'");
  // The frames every tile wrote; a frame some tile lacks is an error (a tile fell behind).
  std::map<int, int> count;
  for (const auto& tile : wall->tiles) {
    for (const int f : framesOf(dir, tile.id)) ++count[f];
  }
  if (count.empty())
    return fail("no tile frames in '" + dir + "' (" + wall->tiles.front().id + "_000000.png, ...)");
  std::vector<int> frames;
  for (const auto& [frame, tiles] : count) {
    if (tiles != static_cast<int>(wall->tiles.size())) {
      for (const auto& tile : wall->tiles) {
        char name[64];
        std::snprintf(name, sizeof name, "_%06d.png", frame);
        if (!fs::exists(dir + "/" + tile.id + name)) {
          return fail("frame " + std::to_string(frame) + " of tile '" + tile.id +
                      "' is missing: '" + dir + "/" + tile.id + name + "'");
        }
      }
    }
    frames.push_back(frame);
  }
  viewer::FrameWriterSettings settings;
  settings.directory = out;
  settings.prefix = prefix;
  settings.format = *frameFormat;
  settings.fps = fps;
  bool opened = false;
  std::optional<viewer::FrameWriter> writer;
  for (const int frame : frames) {
    std::vector<viewer::PlacedImage> tiles;
    for (const auto& tile : wall->tiles) {
      char name[64];
      std::snprintf(name, sizeof name, "_%06d.png", frame);
      auto image = viewer::readPng(dir + "/" + tile.id + name);
      if (!image) return fail(image.error().message);
      tiles.push_back({tile.col, tile.row, std::move(*image)});
    }
    auto mosaic = viewer::stitchWall(*wall, tiles);
    if (!mosaic) return fail("frame " + std::to_string(frame) + ": " + mosaic.error().message);
    if (!opened) {
      settings.width = mosaic->width;
      settings.height = mosaic->height;
      auto made = viewer::FrameWriter::open(settings);
      if (!made) return fail(made.error().message);
      writer = std::move(*made);
      opened = true;
    }
    if (auto written = writer->write(*mosaic); !written) return fail(written.error().message);
  }
  if (auto closed = writer->close(); !closed) return fail(closed.error().message);
  std::fprintf(stderr, "vrflow-wall-mosaic: %zu frame(s) of %zu tiles into %s\n", frames.size(),
               wall->tiles.size(), writer->description().c_str());
  return 0;
}
