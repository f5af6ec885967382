#include "vrflow/viewer/frame_writer.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <utility>

#include "vrflow/base/echo.hpp"
#include "vrflow/base/file_access.hpp"

namespace vrflow::viewer {
namespace {

// Quotes for /bin/sh.
std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

bool ffmpegHasEncoder(const std::string& ffmpeg, const std::string& encoder) {
  const std::string command = shellQuote(ffmpeg) + " -hide_banner -encoders 2>/dev/null";
  std::FILE* out = popen(command.c_str(), "r");
  if (!out) return false;
  std::string text;
  std::array<char, 4096> buffer{};
  while (const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), out)) {
    text.append(buffer.data(), n);
  }
  pclose(out);
  return text.find(" " + encoder + " ") != std::string::npos;
}

}  // namespace

Result<FrameFormat> parseFrameFormat(const std::string& text) {
  if (text == "png") return FrameFormat::Png;
  if (text == "mp4") return FrameFormat::Mp4;
  if (text == "auto") return FrameFormat::Auto;
  return makeError("format must be png, mp4 or auto, got '" + text + "'");
}

std::string findOnPath(const std::string& program) {
  if (program.find('/') != std::string::npos) {
    return access(program.c_str(), X_OK) == 0 ? program : std::string{};
  }
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::string dirs = path;
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
    std::string candidate = dir + "/" + program;
    std::error_code ec;
    if (access(candidate.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(candidate, ec)) {
      return candidate;
    }
    start = end + 1;
  }
  return {};
}

Result<FrameWriter> FrameWriter::open(const FrameWriterSettings& settings) {
  if (settings.width <= 0 || settings.height <= 0) {
    return makeError("frame size must be positive, got " + std::to_string(settings.width) + "x" +
                     std::to_string(settings.height));
  }
  // The folder is created, but its own missing parents only inside the working folder.
  if (auto parent = prepareOutputPath(settings.directory); !parent) {
    return makeError("cannot create output directory " + quotedValue(settings.directory) + ": " +
                     parent.error().message);
  }
  std::error_code ec;
  std::filesystem::create_directory(settings.directory, ec);
  if (!std::filesystem::is_directory(settings.directory, ec)) {
    return makeError("cannot create output directory " + quotedValue(settings.directory));
  }
  FrameWriter writer;
  writer.settings_ = settings;
  const std::string ffmpeg = findOnPath(settings.ffmpeg.empty() ? "ffmpeg" : settings.ffmpeg);
  if (settings.format == FrameFormat::Mp4 && ffmpeg.empty()) {
    return makeError("format mp4 needs ffmpeg, which is not on PATH (use format png or auto)");
  }
  if (settings.format == FrameFormat::Png || ffmpeg.empty()) {
    writer.description_ =
        "PNG frames " + settings.directory + "/" + settings.prefix + "_NNNNNN.png" +
        (settings.format == FrameFormat::Auto ? " (ffmpeg not found on PATH)" : "");
    return writer;
  }
  // Even sizes keep yuv420p happy; the filter pads an odd frame by one pixel.
  const std::string codec = ffmpegHasEncoder(ffmpeg, "libx264")
                                ? "-c:v libx264 -preset veryfast -crf 18"
                                : "-c:v mpeg4 -q:v 3";
  const std::string video = settings.directory + "/" + settings.prefix + ".mp4";
  const std::string command =
      shellQuote(ffmpeg) + " -y -loglevel error -f rawvideo -pixel_format rgb24 -video_size " +
      std::to_string(settings.width) + "x" + std::to_string(settings.height) + " -framerate " +
      std::to_string(settings.fps) + " -i - -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' " + codec +
      " -pix_fmt yuv420p " + shellQuote(video);
  writer.pipe_ = popen(command.c_str(), "w");
  if (!writer.pipe_) return makeError("cannot start ffmpeg: " + command);
  writer.description_ = "MP4 " + video + " (" + ffmpeg + ", " +
                        (codec.find("libx264") != std::string::npos ? "libx264" : "mpeg4") + ")";
  return writer;
}

FrameWriter::FrameWriter(FrameWriter&& other) noexcept
    : settings_(std::move(other.settings_)),
      pipe_(std::exchange(other.pipe_, nullptr)),
      videoClosed_(other.videoClosed_),
      description_(std::move(other.description_)),
      frames_(other.frames_) {}

FrameWriter& FrameWriter::operator=(FrameWriter&& other) noexcept {
  if (this != &other) {
    (void)close();
    settings_ = std::move(other.settings_);
    pipe_ = std::exchange(other.pipe_, nullptr);
    videoClosed_ = other.videoClosed_;
    description_ = std::move(other.description_);
    frames_ = other.frames_;
  }
  return *this;
}

FrameWriter::~FrameWriter() {
  (void)close();
}

Status FrameWriter::write(const Image& image) {
  if (image.width != settings_.width || image.height != settings_.height) {
    return makeError("frame is " + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + ", the output expects " +
                     std::to_string(settings_.width) + "x" + std::to_string(settings_.height));
  }
  if (videoClosed_) return makeError("the video is already closed");
  if (pipe_) {
    if (std::fwrite(image.rgb.data(), 1, image.rgb.size(), pipe_) != image.rgb.size()) {
      return makeError("ffmpeg stopped taking frames (see its messages above)");
    }
    ++frames_;
    return {};
  }
  std::array<char, 32> number{};
  std::snprintf(number.data(), number.size(), "_%06d.png", frames_);
  auto status = writePng(settings_.directory + "/" + settings_.prefix + number.data(), image);
  if (status) ++frames_;
  return status;
}

Status FrameWriter::close() {
  if (!pipe_) return {};
  const int status = pclose(std::exchange(pipe_, nullptr));
  videoClosed_ = true;
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return makeError("ffmpeg failed (status " + std::to_string(status) + ") writing " +
                     settings_.directory + "/" + settings_.prefix + ".mp4");
  }
  return {};
}

}  // namespace vrflow::viewer
