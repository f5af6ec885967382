#include "parallel.hpp"

#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace vrflow::fluid::detail {

namespace {

thread_local bool tInsidePart = false;

inline void cpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

/// Spins until `word` differs from `seen` for at most spinMicros, then sleeps on it until it
/// does; returns the value it saw.
template <typename T>
T awaitChange(const std::atomic<T>& word, T seen, int spinMicros) {
  using Clock = std::chrono::steady_clock;
  const auto until = Clock::now() + std::chrono::microseconds(spinMicros);
  for (unsigned spins = 1; spinMicros > 0; ++spins) {
    const T now = word.load(std::memory_order_acquire);
    if (now != seen) return now;
    cpuRelax();
    if (spins % 64 == 0 && Clock::now() >= until) break;
  }
  for (;;) {
    word.wait(seen, std::memory_order_acquire);
    const T now = word.load(std::memory_order_acquire);
    if (now != seen) return now;
  }
}

}  // namespace

struct Workers::Pool {
  // One loop at a time: the caller writes the job, then bumps `epoch` (release); each helper
  // sees the new epoch (acquire), runs its part if it has one, and takes one off `pending`. The
  // caller writes the next job only once `pending` is zero, so no helper still reads the last.
  std::atomic<std::uint32_t> epoch{0};
  std::atomic<int> pending{0};
  int spinMicros = 0;
  bool stop = false;
  void (*call)(void*, int) = nullptr;
  void* context = nullptr;
  int parts = 0;
  std::mutex errorMutex;
  std::exception_ptr error;
  std::vector<std::thread> helpers;

  void keep(std::exception_ptr e) {
    const std::lock_guard<std::mutex> lock(errorMutex);
    if (!error) error = std::move(e);
  }

  void helperLoop(int part) {
    tInsidePart = true;
    std::uint32_t seen = 0;
    for (;;) {
      seen = awaitChange(epoch, seen, spinMicros);
      if (stop) return;
      if (part < parts) {
        try {
          call(context, part);
        } catch (...) {
          keep(std::current_exception());
        }
      }
      if (pending.fetch_sub(1, std::memory_order_acq_rel) == 1) pending.notify_one();
    }
  }

  /// Starts a loop on the helpers (the fields are written) and returns at once.
  void start() {
    pending.store(static_cast<int>(helpers.size()), std::memory_order_relaxed);
    epoch.fetch_add(1, std::memory_order_release);
    epoch.notify_all();
  }

  void awaitHelpers() {
    int left = pending.load(std::memory_order_acquire);
    while (left != 0) left = awaitChange(pending, left, spinMicros);
  }
};

namespace {

/// The CPUs the calling thread (and the helpers it starts) may run on, or 0 when unknown.
int allowedCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return 0;
  return CPU_COUNT(&set);
}

}  // namespace

Workers::Workers(int threads) : threads_(threads < 1 ? 1 : threads) {
  if (threads_ == 1) return;
  const int cpus = allowedCpus();
  spinMicros_ = cpus == 0 || cpus >= threads_ ? kSpinMicros : 0;
  pool_ = std::make_unique<Pool>();
  pool_->spinMicros = spinMicros_;
  pool_->helpers.reserve(static_cast<std::size_t>(threads_ - 1));
  for (int h = 1; h < threads_; ++h) {
    pool_->helpers.emplace_back([pool = pool_.get(), h] { pool->helperLoop(h); });
  }
}

Workers::~Workers() {
  if (!pool_) return;
  pool_->stop = true;
  pool_->start();
  for (auto& t : pool_->helpers) t.join();
}

bool Workers::insidePart() {
  return tInsidePart;
}

void Workers::dispatch(int parts, void (*call)(void*, int), void* context) const {
  Pool& pool = *pool_;
  pool.call = call;
  pool.context = context;
  pool.parts = parts;
  pool.start();
  tInsidePart = true;
  try {
    call(context, 0);
  } catch (...) {
    pool.keep(std::current_exception());
  }
  tInsidePart = false;
  pool.awaitHelpers();
  if (pool.error) {
    std::exception_ptr e;
    std::swap(e, pool.error);
    std::rethrow_exception(e);
  }
}

}  // namespace vrflow::fluid::detail
