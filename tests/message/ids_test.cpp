#include "vrflow/message/ids.hpp"

#include <gtest/gtest.h>

namespace vrflow::msg {
namespace {

TEST(Ids, PackHostInHighBitsAndCounterInLowBits) {
  const std::uint64_t id = makeId(0x0A000007u, 42);
  EXPECT_EQ(id, 0x0A0000070000002Aull);
  EXPECT_EQ(hostIdOf(id), 0x0A000007u);
  EXPECT_EQ(counterOf(id), 42u);
}

TEST(Ids, RoundTripExtremeValues) {
  const std::uint64_t id = makeId(0xFFFFFFFFu, 0xFFFFFFFFu);
  EXPECT_EQ(hostIdOf(id), 0xFFFFFFFFu);
  EXPECT_EQ(counterOf(id), 0xFFFFFFFFu);
  EXPECT_EQ(makeId(0, 0), kNullId);
}

TEST(HostIdFromAddress, DottedIpv4GivesItsBits) {
  const auto id = hostIdFromAddress("10.0.0.7");
  ASSERT_TRUE(id.ok()) << id.error().message;
  EXPECT_EQ(*id, 0x0A000007u);
  EXPECT_EQ(*hostIdFromAddress("192.168.1.254"), 0xC0A801FEu);
  EXPECT_EQ(*hostIdFromAddress("255.255.255.255"), 0xFFFFFFFFu);
}

TEST(HostIdFromAddress, HostNamesHashWithFnv1a) {
  EXPECT_EQ(*hostIdFromAddress("node01"), fnv1a32("node01"));
  EXPECT_NE(*hostIdFromAddress("node01"), *hostIdFromAddress("node02"));
  // Known FNV-1a 32 values.
  EXPECT_EQ(fnv1a32(""), 0x811C9DC5u);
  EXPECT_EQ(fnv1a32("a"), 0xE40C292Cu);
  EXPECT_EQ(fnv1a32("foobar"), 0xBF9CF968u);
}

TEST(HostIdFromAddress, NonCanonicalDottedTextIsHashedNotParsed) {
  for (const char* text : {"010.0.0.1", "1.2.3", "1.2.3.4.5", "256.0.0.1", "1.2.3.4 ", "::1",
                           "1..2.3", "1.2.3.4567"}) {
    const auto id = hostIdFromAddress(text);
    ASSERT_TRUE(id.ok()) << text;
    EXPECT_EQ(*id, fnv1a32(text)) << text;
  }
}

TEST(HostIdFromAddress, EmptyOrUnspecifiedAddressIsAnError) {
  const auto empty = hostIdFromAddress("");
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().message.find("empty"), std::string::npos);
  EXPECT_FALSE(hostIdFromAddress("0.0.0.0").ok());
}

}  // namespace
}  // namespace vrflow::msg
