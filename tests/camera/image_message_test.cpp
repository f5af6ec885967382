// The image and contour wire forms: round trips, and malformed resources named.
#include "vrflow/camera/image_message.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "vrflow/camera/contour_message.hpp"
#include "vrflow/message/byte_sink.hpp"

namespace vrflow::camera {
namespace {

std::vector<std::byte> rawMessage(std::span<const std::byte> body, std::int64_t captured) {
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  builder.addInt64Stamp(kCaptureStamp, captured);
  builder.addRawResource(9, true, body);
  const std::size_t size = builder.finish();
  return {sink.data(), sink.data() + size};
}

std::vector<std::byte> imageMessage(const cv::Mat& image, std::int64_t captured) {
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  builder.addInt64Stamp(kCaptureStamp, captured);
  addImage(builder, 9, image);
  const std::size_t size = builder.finish();
  return {sink.data(), sink.data() + size};
}

TEST(ImageMessage, ImagesOfOneToFourChannelsComeBackWithTheirCaptureTime) {
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4}) {
    cv::Mat image(7, 13, type);
    cv::randu(image, 0, 256);
    // A region of interest: its rows are not contiguous in memory, the wire packs them.
    const cv::Mat part = image(cv::Rect(2, 1, 9, 5));
    const auto bytes = imageMessage(part, 123456789);
    const auto view = msg::MessageView::parse(bytes);
    ASSERT_TRUE(view.ok()) << view.error().message;
    auto images = readImages(*view);
    ASSERT_TRUE(images.ok()) << images.error().message;
    ASSERT_EQ(images->size(), 1u);
    EXPECT_EQ((*images)[0].type(), type);
    EXPECT_EQ(cv::norm((*images)[0], part, cv::NORM_INF), 0);
    EXPECT_EQ(captureTimeNs(*view), 123456789);
  }
}

TEST(ImageMessage, MalformedImagesAreNamed) {
  const cv::Mat image(4, 5, CV_8UC3, cv::Scalar(1, 2, 3));
  auto good = imageMessage(image, 0);
  const auto parsed = msg::MessageView::parse(good);
  ASSERT_TRUE(parsed.ok());
  const auto body = parsed->begin()->asResource()->raw();
  std::vector<std::byte> copy(body.begin(), body.end());
  struct Case {
    std::size_t offset;
    std::int32_t value;
    std::string expected;
  };
  for (const Case& c : {Case{0, 0, "image expected, no 'VXI1' header"},
                        Case{4, 2, "image version 2, this build reads 1"},
                        Case{8, -5, "image of impossible size -5x4"},
                        Case{16, CV_32FC1, "image of impossible size 5x4 or type 5"},
                        Case{12, 5, "image holds 60 bytes, its header says 5 rows of 15"}}) {
    auto bad = copy;
    std::memcpy(bad.data() + c.offset, &c.value, 4);
    const auto bytes = rawMessage(bad, 0);
    const auto view = msg::MessageView::parse(bytes);
    ASSERT_TRUE(view.ok());
    const auto read = readImage(*view->begin()->asResource());
    ASSERT_FALSE(read.ok()) << c.expected;
    EXPECT_EQ(read.error().message.rfind("resource 9: " + c.expected, 0), 0u)
        << read.error().message;
  }
}

TEST(ContourMessage, ContoursComeBackAndTruncatedOnesAreNamed) {
  const std::vector<std::vector<cv::Point>> contours{{{1, 2}, {3, 4}, {5, -6}}, {}, {{7, 8}}};
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  addContours(builder, 4, contours);
  const std::size_t size = builder.finish();
  const std::vector<std::byte> bytes(sink.data(), sink.data() + size);
  const auto view = msg::MessageView::parse(bytes);
  ASSERT_TRUE(view.ok());
  const auto resource = view->begin()->asResource();
  auto read = readContours(*resource);
  ASSERT_TRUE(read.ok()) << read.error().message;
  EXPECT_EQ(*read, contours);
  const auto body = resource->raw();
  const auto cut = rawMessage(body.first(body.size() - 8), 0);
  const auto cutView = msg::MessageView::parse(cut);
  ASSERT_TRUE(cutView.ok());
  auto truncated = readContours(*cutView->begin()->asResource());
  ASSERT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.error().message, "resource 9: contours cut short");
}

}  // namespace
}  // namespace vrflow::camera
