#pragma once

#include <cstdio>
#include <string>

#include "vrflow/base/result.hpp"
#include "vrflow/viewer/image.hpp"

// Where rendered frames go: numbered PNG files, or an MP4 encoded by an ffmpeg child process.

namespace vrflow::viewer {

/// Output format: PNG frames, MP4 through ffmpeg, or MP4 when ffmpeg is found and PNG otherwise.
enum class FrameFormat { Png, Mp4, Auto };

/// Parses "png", "mp4" or "auto".
Result<FrameFormat> parseFrameFormat(const std::string& text);

/// The full path of `program` found on PATH, or "" when it is not there.
std::string findOnPath(const std::string& program);

/// What a FrameWriter was asked for.
struct FrameWriterSettings {
  std::string directory = ".";   ///< created if missing
  std::string prefix = "frame";  ///< PNG files are PREFIX_000000.png; the video PREFIX.mp4
  FrameFormat format = FrameFormat::Auto;
  int width = 0;
  int height = 0;
  double fps = 30.0;   ///< frame rate written into the MP4
  std::string ffmpeg;  ///< the ffmpeg to run; "" looks it up on PATH
};

/// Writes frames one by one. For MP4 it pipes raw RGB into `ffmpeg -f rawvideo` encoding with
/// libx264 (yuv420p), or mpeg4 when ffmpeg has no libx264.
class FrameWriter {
 public:
  /// Opens the output. Format Mp4 without ffmpeg is an error; Auto falls back to PNG.
  static Result<FrameWriter> open(const FrameWriterSettings& settings);
  FrameWriter(FrameWriter&& other) noexcept;
  FrameWriter& operator=(FrameWriter&& other) noexcept;
  ~FrameWriter();

  /// Writes one frame (width x height as opened).
  Status write(const Image& image);
  /// Ends the video (waits for ffmpeg); further writes fail. Called by the destructor too.
  Status close();

  /// True when frames go to ffmpeg.
  bool video() const { return pipe_ != nullptr || videoClosed_; }
  /// One line for the log: what is written where ("PNG frames dir/frame_NNNNNN.png", ...).
  const std::string& description() const { return description_; }
  /// Frames written so far.
  int frames() const { return frames_; }

 private:
  FrameWriter() = default;
  FrameWriterSettings settings_;
  std::FILE* pipe_ = nullptr;
  bool videoClosed_ = false;
  std::string description_;
  int frames_ = 0;
};

}  // namespace vrflow::viewer
