// The fluid solver's pool of threads (Workers): each part runs once, on its own fixed thread,
// with the ranges forRanges promises; loops follow each other without losing or repeating a
// part, whether the helpers spin or sleep between them; a part's exception reaches the caller
// and the pool goes on; a loop started from inside a part runs on the calling thread.
#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "parallel.hpp"

using vrflow::fluid::detail::Workers;

namespace {

struct Part {
  std::size_t begin = 0, end = 0;
  std::thread::id thread;
  int runs = 0;
};

std::vector<Part> runOnce(const Workers& workers, int parts, std::size_t n) {
  std::vector<Part> seen(static_cast<std::size_t>(parts));
  workers.forRanges(parts, n, [&](std::size_t part, std::size_t begin, std::size_t end) {
    auto& p = seen.at(part);
    p.begin = begin;
    p.end = end;
    p.thread = std::this_thread::get_id();
    ++p.runs;
  });
  return seen;
}

}  // namespace

TEST(FluidWorkers, EveryPartRunsOnceOverItsRangeOnItsOwnThread) {
  for (int threads : {1, 2, 3, 5}) {
    const Workers workers(threads);
    EXPECT_EQ(workers.threads(), threads);
    for (int parts = 1; parts <= threads; ++parts) {
      for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}}) {
        const auto seen = runOnce(workers, parts, n);
        std::set<std::thread::id> threadsUsed;
        for (int r = 0; r < parts; ++r) {
          const auto& p = seen[static_cast<std::size_t>(r)];
          const auto part = static_cast<std::size_t>(r), total = static_cast<std::size_t>(parts);
          EXPECT_EQ(p.runs, 1) << threads << " " << parts << " " << n;
          EXPECT_EQ(p.begin, n * part / total);
          EXPECT_EQ(p.end, n * (part + 1) / total);
          threadsUsed.insert(p.thread);
        }
        EXPECT_EQ(threadsUsed.size(), static_cast<std::size_t>(parts)) << "parts share a thread";
        EXPECT_EQ(seen[0].thread, std::this_thread::get_id()) << "the caller runs part 0";
      }
    }
  }
}

TEST(FluidWorkers, APartKeepsItsThreadFromLoopToLoop) {
  const Workers workers(3);
  const auto first = runOnce(workers, 3, 30);
  for (int loop = 0; loop < 50; ++loop) {
    const auto again = runOnce(workers, 3, 30);
    for (std::size_t r = 0; r < 3; ++r) EXPECT_EQ(again[r].thread, first[r].thread) << loop;
  }
}

TEST(FluidWorkers, ManyLoopsBackToBackAndAfterSleepingLoseNoPart) {
  // Back to back the helpers stay awake; with pauses longer than their spin they sleep and are
  // woken: both ways every element is added exactly once per loop.
  const Workers workers(3);
  std::vector<int> count(997, 0);
  int loops = 0;
  for (int pause : {0, 0, 0, 3 * Workers::kSpinMicros}) {
    for (int i = 0; i < 400; ++i) {
      workers.forRanges(3, count.size(), [&](std::size_t, std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) ++count[k];
      });
      ++loops;
      if (pause > 0 && i % 20 == 0) std::this_thread::sleep_for(std::chrono::microseconds(pause));
    }
  }
  for (std::size_t k = 0; k < count.size(); ++k) ASSERT_EQ(count[k], loops) << k;
}

TEST(FluidWorkers, FewerPartsThanThreadsLeaveTheOtherHelpersOut) {
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

TEST(FluidWorkers, AnExceptionInAHelpersPartReachesTheCallerAndThePoolGoesOn) {
  const Workers workers(2);
  EXPECT_THROW(workers.forRanges(2, 10,
                                 [&](std::size_t part, std::size_t, std::size_t) {
                                   if (part == 1) throw std::runtime_error("part 1 failed");
                                 }),
               std::runtime_error);
  EXPECT_THROW(workers.forRanges(2, 10,
                                 [&](std::size_t part, std::size_t, std::size_t) {
                                   if (part == 0) throw std::logic_error("part 0 failed");
                                 }),
               std::logic_error);
  const auto seen = runOnce(workers, 2, 10);
  EXPECT_EQ(seen[0].runs, 1);
  EXPECT_EQ(seen[1].runs, 1);
}

TEST(FluidWorkers, ALoopStartedInsideAPartRunsOnTheCallingThread) {
  const Workers workers(2);
  std::mutex m;
  std::map<std::size_t, std::vector<std::thread::id>> inner;
  std::vector<std::thread::id> outer(2);
  workers.forRanges(2, 2, [&](std::size_t part, std::size_t, std::size_t) {
    outer[part] = std::this_thread::get_id();
    workers.forRanges(2, 4, [&](std::size_t, std::size_t, std::size_t) {
      const std::lock_guard<std::mutex> lock(m);
      inner[part].push_back(std::this_thread::get_id());
    });
  });
  for (std::size_t part = 0; part < 2; ++part) {
    ASSERT_EQ(inner[part].size(), 2u);
    for (const auto& id : inner[part]) EXPECT_EQ(id, outer[part]);
  }
}

TEST(FluidWorkers, NoThreadCountBelowOne) {
  const Workers none(0), negative(-3);
  EXPECT_EQ(none.threads(), 1);
  EXPECT_EQ(negative.threads(), 1);
  EXPECT_EQ(runOnce(none, 1, 5)[0].end, 5u);
}

// A pool with more threads than the CPUs it may use (a rank bound to one core) does not spin:
// a spinning helper would hold the core its caller needs.
TEST(FluidWorkers, NoSpinningWhenThereAreMoreThreadsThanAllowedCpus) {
  cpu_set_t before;
  ASSERT_EQ(sched_getaffinity(0, sizeof(before), &before), 0);
  int first = -1;
  for (int c = 0; c < CPU_SETSIZE && first < 0; ++c) {
    if (CPU_ISSET(c, &before)) first = c;
  }
  ASSERT_GE(first, 0);
  if (CPU_COUNT(&before) >= 2) {
    const Workers spinning(2);
    EXPECT_EQ(spinning.spinMicros(), Workers::kSpinMicros);
  }
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(first, &one);
  ASSERT_EQ(sched_setaffinity(0, sizeof(one), &one), 0);
  {
    const Workers bound(2);
    EXPECT_EQ(bound.spinMicros(), 0);
    std::vector<int> count(100, 0);
    for (int i = 0; i < 200; ++i) {
      bound.forRanges(2, count.size(), [&](std::size_t, std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) ++count[k];
      });
    }
    for (int c : count) EXPECT_EQ(c, 200);
  }
  ASSERT_EQ(sched_setaffinity(0, sizeof(before), &before), 0);
}

TEST(FluidWorkers, PoolsComeAndGoWhileTheirHelpersSleepOrSpin) {
  for (int i = 0; i < 20; ++i) {
    const Workers workers(3);
    runOnce(workers, 3, 9);
    if (i % 2 == 0)
      std::this_thread::sleep_for(std::chrono::microseconds(3 * Workers::kSpinMicros));
  }
  SUCCEED();
}
