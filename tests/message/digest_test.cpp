#include "vrflow/message/digest.hpp"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <vector>

#include "sample_messages.hpp"

namespace vrflow::msg {
namespace {

using testing::finished;
using testing::sampleStamps;

// Builds the sample scene's rigid body update with the given stamps and position.
std::vector<std::byte> update(const Stamps& stamps, const Vec3& position) {
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setStamps(stamps);
  builder.addObject(makeId(1, 1), rigidType()).set(RigidParam::kPosition, position);
  return finished(builder);
}

std::uint64_t digestOf(const std::vector<std::byte>& bytes) {
  const auto view = MessageView::parse(bytes);
  EXPECT_TRUE(view.ok());
  return view.ok() ? digest(*view) : 0;
}

TEST(Digest, IgnoresTheSendTime) {
  Stamps early = sampleStamps();
  Stamps late = sampleStamps();
  early.sendTimeNs = 1;
  late.sendTimeNs = 999'999'999'999;
  const auto a = update(early, {1, 2, 3});
  const auto b = update(late, {1, 2, 3});
  EXPECT_NE(a, b);
  EXPECT_EQ(digestOf(a), digestOf(b));
}

TEST(Digest, ChangesWithEveryDeterministicStampAndWithChunkContent) {
  const Stamps base = sampleStamps();
  const std::uint64_t reference = digestOf(update(base, {1, 2, 3}));
  EXPECT_EQ(digestOf(update(base, {1, 2, 3})), reference);  // stable

  std::vector<Stamps> variants(6, base);
  variants[0].source = "other";
  variants[1].iteration += 1;
  variants[2].simTime += 0.5;
  variants[3].timeStep *= 2;
  std::get<std::int64_t>(variants[4].user[0].value) = 8;
  variants[5].user.pop_back();
  for (const Stamps& stamps : variants) EXPECT_NE(digestOf(update(stamps, {1, 2, 3})), reference);
  EXPECT_NE(digestOf(update(base, {1, 2, 3.0000001})), reference);
}

TEST(Digest, IsXxh3OfTheBytesWithTheSendTimeZeroed) {
  // The documented definition, so that other tools can compute the same digest; small and large
  // messages take different paths inside digest().
  for (const std::size_t payload : {std::size_t{16}, std::size_t{5000}}) {
    const std::vector<std::byte> blob(payload, std::byte{0x5A});
    auto build = [&](std::uint64_t sendTimeNs) {
      VectorSink sink;
      MessageBuilder builder(sink);
      Stamps stamps = sampleStamps();
      stamps.sendTimeNs = sendTimeNs;
      builder.setStamps(stamps);
      builder.addRawResource(5, false, blob);
      return finished(builder);
    };
    const auto unsent = build(0);
    const auto sent = build(42);
    EXPECT_EQ(digestOf(sent), XXH3_64bits(unsent.data(), unsent.size())) << payload;
  }
}

}  // namespace
}  // namespace vrflow::msg
