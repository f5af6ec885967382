// The fluid solver's threads inside a block (detail::Workers, src/parallel.hpp): each part runs
// once over the range forRanges promises, loops follow each other without losing or repeating a
// part (back to back, and after the workers went to sleep), a part's exception reaches the
// caller and the workers go on, a loop started inside a part completes.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "parallel.hpp"

using vrflow::fluid::detail::Workers;

namespace {

struct Part {
  std::size_t begin = 0, end = 0;
  int runs = 0;
};

std::vector<Part> runOnce(const Workers& workers, int parts, std::size_t n) {
  std::vector<Part> seen(static_cast<std::size_t>(parts));
  workers.forRanges(parts, n, [&](std::size_t part, std::size_t begin, std::size_t end) {
    auto& p = seen.at(part);
    p.begin = begin;
    p.end = end;
    ++p.runs;
  });
  return seen;
}

}  // namespace

TEST(FluidWorkers, EveryPartRunsOnceOverItsRange) {
  for (int threads : {1, 2, 3, 5}) {
    const Workers workers(threads);
    EXPECT_EQ(workers.threads(), threads);
    for (int parts = 1; parts <= threads; ++parts) {
      for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}}) {
        const auto seen = runOnce(workers, parts, n);
        for (int r = 0; r < parts; ++r) {
          const auto& p = seen[static_cast<std::size_t>(r)];
          const auto part = static_cast<std::size_t>(r), total = static_cast<std::size_t>(parts);
          EXPECT_EQ(p.runs, 1) << threads << " " << parts << " " << n;
          EXPECT_EQ(p.begin, n * part / total);
          EXPECT_EQ(p.end, n * (part + 1) / total);
        }
      }
    }
  }
}

TEST(FluidWorkers, ManyLoopsBackToBackAndAfterSleepingLoseNoPart) {
  const Workers workers(3);
  std::vector<int> count(997, 0);
  int loops = 0;
  for (bool pause : {false, true}) {
    for (int i = 0; i < 400; ++i) {
      workers.forRanges(3, count.size(), [&](std::size_t, std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) ++count[k];
      });
      ++loops;
      if (pause && i % 40 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  for (std::size_t k = 0; k < count.size(); ++k) ASSERT_EQ(count[k], loops) << k;
}

TEST(FluidWorkers, FewerPartsThanThreads) {
  const Workers workers(4);
  std::atomic<int> calls{0};
  for (int i = 0; i < 200; ++i) {
    workers.forRanges(2, 10, [&](std::size_t part, std::size_t, std::size_t) {
      EXPECT_LT(part, 2u);
      ++calls;
    });
  }
  EXPECT_EQ(calls.load(), 400);
}

TEST(FluidWorkers, AnExceptionInAPartReachesTheCallerAndTheWorkersGoOn) {
  const Workers workers(2);
  for (std::size_t failing : {0u, 1u}) {
    EXPECT_THROW(workers.forRanges(2, 10,
                                   [&](std::size_t part, std::size_t, std::size_t) {
                                     if (part == failing) throw std::runtime_error("part failed");
                                   }),
                 std::runtime_error);
  }
  const auto seen = runOnce(workers, 2, 10);
  EXPECT_EQ(seen[0].runs, 1);
  EXPECT_EQ(seen[1].runs, 1);
}

TEST(FluidWorkers, ALoopStartedInsideAPartCompletes) {
  const Workers workers(2);
  std::atomic<int> inner{0};
  workers.forRanges(2, 2, [&](std::size_t, std::size_t, std::size_t) {
    workers.forRanges(
        2, 4, [&](std::size_t, std::size_t b, std::size_t e) { inner += static_cast<int>(e - b); });
  });
  EXPECT_EQ(inner.load(), 8);
}

TEST(FluidWorkers, NoThreadCountBelowOne) {
  const Workers none(0), negative(-3);
  EXPECT_EQ(none.threads(), 1);
  EXPECT_EQ(negative.threads(), 1);
  const auto seen = runOnce(none, none.threads(), 5);
  EXPECT_EQ(seen[0].end, 5u);
}
