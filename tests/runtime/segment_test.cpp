#include "vrflow/ipc/segment.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <thread>
#include <vector>

#include "vrflow/ipc/doorbell.hpp"
#include "vrflow/ipc/ring.hpp"

namespace vrflow::ipc {
namespace {

TEST(Segment, ReleasedBlocksAreReusedForTheSameSizeClass) {
  auto segment = Segment::create(8 << 20);
  ASSERT_TRUE(segment.ok()) << segment.error().message;
  const uint64_t a = segment->allocate(100);
  ASSERT_NE(a, 0u);
  EXPECT_GE(segment->payloadCapacity(a), 100u);
  segment->release(a);
  EXPECT_EQ(segment->allocate(90), a);
}

TEST(Segment, BlockIsFreedOnlyWhenTheLastReferenceIsDropped) {
  auto segment = Segment::create(8 << 20);
  ASSERT_TRUE(segment.ok());
  const uint64_t a = segment->allocate(1000);
  segment->retain(a);
  segment->release(a);
  EXPECT_NE(segment->allocate(1000), a);  // still held once
  segment->release(a);
  EXPECT_EQ(segment->header().inUseBytes.load(), 2048u);  // only the second block remains
}

TEST(Segment, ExhaustionReturnsNoBlockInsteadOfCrashing) {
  auto segment = Segment::create(2 << 20);
  ASSERT_TRUE(segment.ok());
  EXPECT_EQ(segment->allocate(4 << 20), 0u);
  EXPECT_EQ(segment->allocate(std::size_t{1} << 40), 0u);
}

TEST(Segment, ForgedHandlesAreRecognised) {
  auto segment = Segment::create(2 << 20);
  ASSERT_TRUE(segment.ok());
  const uint64_t a = segment->allocate(10);
  EXPECT_TRUE(segment->validHandle(a));
  EXPECT_FALSE(segment->validHandle(0));
  EXPECT_FALSE(segment->validHandle(a + 8));
  EXPECT_FALSE(segment->validHandle(uint64_t{1} << 40));
}

TEST(Segment, ConcurrentAllocationAndReleaseKeepsAccountsBalanced) {
  auto segment = Segment::create(64 << 20);
  ASSERT_TRUE(segment.ok());
  auto work = [&] {
    std::vector<uint64_t> held;
    for (int i = 0; i < 20000; ++i) {
      held.push_back(segment->allocate(static_cast<std::size_t>(64 + (i % 7) * 200)));
      if (held.size() > 8) {
        segment->release(held.front());
        held.erase(held.begin());
      }
    }
    for (auto h : held) segment->release(h);
  };
  std::thread a(work), b(work);
  a.join();
  b.join();
  EXPECT_EQ(segment->header().inUseBytes.load(), 0u);
}

TEST(Ring, DeliversEveryHandleInOrderAcrossThreads) {
  std::vector<std::byte> memory(Ring::bytesFor(64) + 64);
  auto* ring = new (memory.data()) Ring();
  ring->init(64);
  Doorbell bell;
  constexpr uint64_t kCount = 200000;
  std::thread producer([&] {
    for (uint64_t i = 1; i <= kCount; ++i) {
      while (!ring->push(i)) std::this_thread::yield();
      bell.ring();
    }
  });
  uint64_t expected = 1;
  while (expected <= kCount) {
    const uint32_t seen = bell.prepare();
    uint64_t value = 0;
    if (ring->pop(value)) {
      ASSERT_EQ(value, expected);
      ++expected;
      continue;
    }
    bell.sleep(seen, 10'000'000);
  }
  producer.join();
  EXPECT_TRUE(ring->empty());
}

}  // namespace
}  // namespace vrflow::ipc
