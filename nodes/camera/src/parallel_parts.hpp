#pragma once
// The vision core's threads: a loop over [0, n) cut into contiguous parts run on a oneTBB arena
// of `threads` threads (the caller's among them). The library owns no thread pool: an arena is
// made for the call. Callers write per item only, so no result depends on the thread count.

#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <cstddef>

namespace vrflow::camera {

/// Runs work(begin, end) over consecutive parts of [0, n): in the caller alone when threads <= 1,
/// else over 4 parts per thread (for balance) on an arena of `threads`.
template <typename Work>
void forParts(int threads, std::size_t n, Work&& work) {
  if (threads <= 1 || n < 2) {
    work(std::size_t{0}, n);
    return;
  }
  const std::size_t parts = std::min(n, static_cast<std::size_t>(threads) * 4);
  // More threads than cores only splits the same parts finer (and makes oneTBB warn).
  oneapi::tbb::task_arena arena(std::min(threads, oneapi::tbb::info::default_concurrency()));
  arena.execute([&] {
    oneapi::tbb::parallel_for(std::size_t{0}, parts, [&](std::size_t part) {
      work(n * part / parts, n * (part + 1) / parts);
    });
  });
}

}  // namespace vrflow::camera
