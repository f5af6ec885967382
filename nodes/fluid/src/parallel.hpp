#pragma once

#include <cstddef>

// The solver's threads inside a block (FluidSettings::threads), through OpenMP from GCC: a loop
// is cut into one contiguous range per thread, fixed by the count alone (a static schedule), so
// the work a thread does is known in advance. Every loop run this way either writes per item
// only (the same bits whatever the thread count) or is arranged so that sums keep the serial
// order (splatParticles).

namespace vrflow::fluid::detail {

/// Runs f(begin, end) over `parts` consecutive ranges of [0, n), part r on a thread of its own
/// when threads > 1 (part r = [n r / parts, n (r + 1) / parts)).
template <typename F>
void forRanges(int threads, int parts, std::size_t n, F&& f) {
  const auto total = static_cast<std::size_t>(parts);
#pragma omp parallel for schedule(static, 1) num_threads(threads) if (threads > 1)
  for (int r = 0; r < parts; ++r) {
    const auto part = static_cast<std::size_t>(r);
    f(n * part / total, n * (part + 1) / total);
  }
}

}  // namespace vrflow::fluid::detail
