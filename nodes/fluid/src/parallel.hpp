#pragma once

#include <cstddef>
#include <memory>

// The solver's threads inside a block (FluidSettings::threads): a loop is cut into one
// contiguous range per part, fixed by the counts alone, and part r always runs on thread r (the
// calling thread runs part 0), so the work of a part never depends on a scheduler. Every loop
// run this way either writes per item only (the same bits whatever the thread count) or is
// arranged so that sums keep the serial order (splatParticles).
//
// Our own small pool rather than a general scheduler: a step runs a few hundred short loops (the
// multigrid cycle's passes on the coarse levels take microseconds), and on a virtual machine whose
// idle cores halt, handing each loop to a sleeping thread costs tens of microseconds (measured:
// 26-77 µs per loop through a oneTBB arena on the project's 2-core VM, more than the loop itself).
// A helper therefore waits for the next loop by spinning for at most kSpinMicros after its part,
// then sleeps on a futex (std::atomic::wait); the caller waits for the helpers the same way. So a
// block that steps keeps its helpers awake between its loops, and a block that waits for its
// inputs has no thread spinning after kSpinMicros. When the process may run on fewer CPUs than
// it has threads (an MPI rank bound to one core, `taskset`), a spinning thread would take its
// core from the thread it waits for: then no thread spins. (OpenMP was not used: libgomp's spin
// length is fixed when the library loads and made two threads five times slower than one on a
// loaded 2-core machine.)

namespace vrflow::fluid::detail {

/// A solver's threads: the calling thread and threads - 1 helpers.
class Workers {
 public:
  /// How long a waiting thread spins before it sleeps (see above).
  static constexpr int kSpinMicros = 100;

  explicit Workers(int threads);
  ~Workers();
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  int threads() const { return threads_; }
  /// How long this pool's threads spin before they sleep: kSpinMicros, or 0 when the process
  /// was allowed fewer CPUs than threads() when the pool was made.
  int spinMicros() const { return spinMicros_; }

  /// Runs f(part, begin, end) over `parts` consecutive ranges of [0, n) (part r = [n r /
  /// parts, n (r + 1) / parts)), part r on thread r, and returns when all are done. `parts` is
  /// at most threads(). Called from inside a part, it runs the parts one after another on the
  /// calling thread. An exception thrown by a part is rethrown here (the first one).
  template <typename F>
  void forRanges(int parts, std::size_t n, F&& f) const {
    const auto total = static_cast<std::size_t>(parts);
    auto run = [&](int r) {
      const auto part = static_cast<std::size_t>(r);
      f(part, n * part / total, n * (part + 1) / total);
    };
    if (!pool_ || parts <= 1 || insidePart()) {
      for (int r = 0; r < parts; ++r) run(r);
      return;
    }
    dispatch(
        parts, [](void* context, int r) { (*static_cast<decltype(run)*>(context))(r); }, &run);
  }

 private:
  struct Pool;
  static bool insidePart();
  void dispatch(int parts, void (*call)(void*, int), void* context) const;

  int threads_ = 1;
  int spinMicros_ = 0;
  std::unique_ptr<Pool> pool_;
};

}  // namespace vrflow::fluid::detail
