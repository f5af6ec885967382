#pragma once

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <cstddef>
#include <memory>

// The solver's threads inside a block (FluidSettings::threads), through oneTBB: a loop is cut
// into one contiguous range per part, fixed by the counts alone, so the work of a part never
// depends on the scheduler. Every loop run this way either writes per item only (the same bits
// whatever the thread count) or is arranged so that sums keep the serial order
// (splatParticles). oneTBB rather than OpenMP: its idle workers yield and then sleep, where
// libgomp's spin (its default wait policy, fixed when the library loads) made two threads five
// times slower than one on this project's loaded 2-core machine.

namespace vrflow::fluid::detail {

/// A solver's threads: an arena of that many (the calling thread among them).
class Workers {
 public:
  explicit Workers(int threads) : threads_(threads < 1 ? 1 : threads) {
    if (threads_ > 1) arena_ = std::make_unique<oneapi::tbb::task_arena>(threads_);
  }

  int threads() const { return threads_; }

  /// Runs f(part, begin, end) over `parts` consecutive ranges of [0, n) (part r = [n r /
  /// parts, n (r + 1) / parts)), on the arena's threads when there are several.
  template <typename F>
  void forRanges(int parts, std::size_t n, F&& f) const {
    const auto total = static_cast<std::size_t>(parts);
    auto run = [&](int r) {
      const auto part = static_cast<std::size_t>(r);
      f(part, n * part / total, n * (part + 1) / total);
    };
    if (!arena_ || parts <= 1) {
      for (int r = 0; r < parts; ++r) run(r);
      return;
    }
    arena_->execute(
        [&] { oneapi::tbb::parallel_for(0, parts, 1, run, oneapi::tbb::static_partitioner()); });
  }

 private:
  int threads_ = 1;
  std::unique_ptr<oneapi::tbb::task_arena> arena_;
};

}  // namespace vrflow::fluid::detail
