#include <gtest/gtest.h>

#include <vector>

#include "vrflow/net/frame.hpp"

namespace vrflow::net {
namespace {

std::vector<std::byte> frame(FrameType type, uint32_t channel, std::vector<std::byte> payload) {
  std::vector<std::byte> bytes(kFrameHeaderBytes);
  encodeHeader({type, channel, static_cast<uint32_t>(payload.size())}, bytes.data());
  bytes.insert(bytes.end(), payload.begin(), payload.end());
  return bytes;
}

struct Collected {
  std::vector<FrameHeader> headers;
  std::vector<std::vector<std::byte>> payloads;
  std::vector<std::byte> storage;
};

FrameReader reader(Collected& c, uint32_t limit = 1024) {
  return FrameReader(
      limit,
      [&c](const FrameHeader& h) {
        c.storage.assign(h.length, std::byte{0});
        return std::span<std::byte>(c.storage);
      },
      [&c](const FrameHeader& h, std::span<const std::byte> p) -> Status {
        c.headers.push_back(h);
        c.payloads.emplace_back(p.begin(), p.end());
        return {};
      });
}

TEST(FrameReader, DeliversFramesSplitAtEveryByte) {
  Collected c;
  auto r = reader(c);
  r.setAuthenticated(true);
  std::vector<std::byte> stream =
      frame(FrameType::Message, 7, std::vector<std::byte>(100, std::byte{5}));
  const auto credit = frame(FrameType::Credit, 7, std::vector<std::byte>(4, std::byte{1}));
  stream.insert(stream.end(), credit.begin(), credit.end());
  for (const std::byte b : stream) ASSERT_TRUE(r.feed({&b, 1}).ok());
  ASSERT_EQ(c.headers.size(), 2u);
  EXPECT_EQ(c.headers[0].type, FrameType::Message);
  EXPECT_EQ(c.headers[0].channel, 7u);
  EXPECT_EQ(c.payloads[0], std::vector<std::byte>(100, std::byte{5}));
  EXPECT_EQ(c.headers[1].type, FrameType::Credit);
  EXPECT_TRUE(r.idle());
}

TEST(FrameReader, LargePayloadIsReadStraightIntoTheTarget) {
  Collected c;
  auto r = reader(c);
  r.setAuthenticated(true);
  auto bytes = frame(FrameType::Message, 1, std::vector<std::byte>(600, std::byte{9}));
  ASSERT_TRUE(r.feed({bytes.data(), kFrameHeaderBytes + 10}).ok());
  auto target = r.directTarget();
  ASSERT_EQ(target.size(), 590u);
  std::fill(target.begin(), target.end(), std::byte{9});
  ASSERT_TRUE(r.advanceDirect(590).ok());
  ASSERT_EQ(c.payloads.size(), 1u);
  EXPECT_EQ(c.payloads[0], std::vector<std::byte>(600, std::byte{9}));
}

TEST(FrameReader, RefusesAMessageBeforeAuthentication) {
  Collected c;
  auto r = reader(c);
  const auto bytes = frame(FrameType::Message, 0, std::vector<std::byte>(8));
  const Status status = r.feed(bytes);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("unauthenticated"), std::string::npos);
  EXPECT_TRUE(c.headers.empty());
}

TEST(FrameReader, RefusesAFrameOverTheLimitBeforeAllocating) {
  Collected c;
  auto r = reader(c, 1000);
  r.setAuthenticated(true);
  std::vector<std::byte> header(kFrameHeaderBytes);
  encodeHeader({FrameType::Message, 0, 1001}, header.data());
  const Status status = r.feed(header);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("exceeds the limit of 1000"), std::string::npos);
  EXPECT_TRUE(c.storage.empty());
}

TEST(FrameReader, RefusesBadMagicUnknownTypeAndWrongControlSizes) {
  {
    Collected c;
    auto r = reader(c);
    auto bytes = frame(FrameType::Hello, 0, std::vector<std::byte>(48));
    bytes[0] = std::byte{'X'};
    EXPECT_NE(r.feed(bytes).error().message.find("bad magic"), std::string::npos);
  }
  {
    Collected c;
    auto r = reader(c);
    auto bytes = frame(FrameType::Hello, 0, {});
    bytes[4] = std::byte{99};
    EXPECT_NE(r.feed(bytes).error().message.find("unknown frame type 99"), std::string::npos);
  }
  {
    Collected c;
    auto r = reader(c);
    r.setAuthenticated(true);
    const auto bytes = frame(FrameType::Credit, 0, std::vector<std::byte>(5));
    EXPECT_NE(r.feed(bytes).error().message.find("expected 4"), std::string::npos);
  }
  {
    Collected c;
    auto r = reader(c);
    r.setAuthenticated(true);
    const auto bytes = frame(FrameType::Hello, 0, std::vector<std::byte>(48));
    EXPECT_NE(r.feed(bytes).error().message.find("after authentication"), std::string::npos);
  }
}

}  // namespace
}  // namespace vrflow::net
