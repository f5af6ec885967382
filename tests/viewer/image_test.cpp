// PNG files round-trip through libpng; frames go to numbered PNGs or an MP4.
#include "vrflow/viewer/image.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "vrflow/viewer/frame_writer.hpp"

namespace vrflow::viewer {
namespace {

namespace fs = std::filesystem;

struct TempFolder {
  fs::path path;
  TempFolder() {
    char pattern[] = "/tmp/vrflow-viewer-test-XXXXXX";
    path = mkdtemp(pattern);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

Image gradient(int width, int height) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(static_cast<std::size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
      image.rgb[i] = static_cast<std::uint8_t>(x * 255 / (width - 1));
      image.rgb[i + 1] = static_cast<std::uint8_t>(y * 255 / (height - 1));
      image.rgb[i + 2] = static_cast<std::uint8_t>((x * 7 + y * 13) % 256);
    }
  }
  return image;
}

TEST(Png, WrittenFileReadsBackIdentical) {
  TempFolder dir;
  const Image image = gradient(37, 23);  // odd sizes: no row padding assumption
  const auto path = (dir.path / "g.png").string();
  ASSERT_TRUE(writePng(path, image).ok());
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const auto back = readPng(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->width, image.width);
  EXPECT_EQ(back->height, image.height);
  EXPECT_EQ(back->rgb, image.rgb);
}

TEST(Png, ReadingAFileThatIsNotAPngFailsWithItsName) {
  TempFolder dir;
  const auto path = (dir.path / "not.png").string();
  std::ofstream(path) << "hello, not a png";
  const auto back = readPng(path);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find(path), std::string::npos);
}

TEST(Png, WritingIntoAMissingFolderFails) {
  const auto status = writePng("/nonexistent-folder/x.png", gradient(4, 4));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("/nonexistent-folder/x.png"), std::string::npos);
}

TEST(FrameWriter, PngFormatWritesNumberedFrames) {
  TempFolder dir;
  FrameWriterSettings settings;
  settings.directory = (dir.path / "frames").string();  // created
  settings.format = FrameFormat::Png;
  settings.width = 16;
  settings.height = 8;
  auto writer = FrameWriter::open(settings);
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  EXPECT_FALSE(writer->video());
  const Image image = gradient(16, 8);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(writer->write(image).ok());
  EXPECT_EQ(writer->frames(), 3);
  for (const char* name : {"frame_000000.png", "frame_000001.png", "frame_000002.png"}) {
    const auto back = readPng((fs::path(settings.directory) / name).string());
    ASSERT_TRUE(back.ok()) << name;
    EXPECT_EQ(back->rgb, image.rgb);
  }
  EXPECT_FALSE(fs::exists(fs::path(settings.directory) / "frame_000003.png"));
  // A frame of another size is refused.
  EXPECT_FALSE(writer->write(gradient(8, 8)).ok());
}

TEST(FrameWriter, AutoFallsBackToPngWithoutFfmpeg) {
  TempFolder dir;
  FrameWriterSettings settings;
  settings.directory = dir.path.string();
  settings.format = FrameFormat::Auto;
  settings.ffmpeg = "/nonexistent/ffmpeg";
  settings.width = 4;
  settings.height = 4;
  auto writer = FrameWriter::open(settings);
  ASSERT_TRUE(writer.ok());
  EXPECT_FALSE(writer->video());
  EXPECT_NE(writer->description().find("PNG"), std::string::npos);
  settings.format = FrameFormat::Mp4;
  const auto mp4 = FrameWriter::open(settings);
  ASSERT_FALSE(mp4.ok());
  EXPECT_NE(mp4.error().message.find("ffmpeg"), std::string::npos);
}

TEST(FrameWriter, Mp4ThroughFfmpegWhenPresent) {
  if (findOnPath("ffmpeg").empty()) GTEST_SKIP() << "ffmpeg is not on PATH; the PNG path is tested";
  TempFolder dir;
  FrameWriterSettings settings;
  settings.directory = dir.path.string();
  settings.format = FrameFormat::Mp4;
  settings.width = 33;  // odd: padded to even for yuv420p
  settings.height = 20;
  {
    auto writer = FrameWriter::open(settings);
    ASSERT_TRUE(writer.ok()) << writer.error().message;
    EXPECT_TRUE(writer->video());
    const Image image = gradient(33, 20);
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(writer->write(image).ok());
    ASSERT_TRUE(writer->close().ok());
  }
  const auto video = dir.path / "frame.mp4";
  ASSERT_TRUE(fs::exists(video));
  std::ifstream in(video, std::ios::binary);
  char header[8] = {};
  in.read(header, 8);
  EXPECT_EQ(std::string(header + 4, 4), "ftyp");  // an ISO media file
  EXPECT_TRUE(fs::directory_iterator(dir.path) != fs::directory_iterator());
  for (const auto& entry : fs::directory_iterator(dir.path)) {
    EXPECT_NE(entry.path().extension(), ".png");
  }
}

TEST(FrameFormat, ParsesTheThreeNamesOnly) {
  EXPECT_EQ(*parseFrameFormat("png"), FrameFormat::Png);
  EXPECT_EQ(*parseFrameFormat("mp4"), FrameFormat::Mp4);
  EXPECT_EQ(*parseFrameFormat("auto"), FrameFormat::Auto);
  EXPECT_FALSE(parseFrameFormat("gif").ok());
}

}  // namespace
}  // namespace vrflow::viewer
