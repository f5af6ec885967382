#include "vrflow/ipc/doorbell.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <ctime>

namespace vrflow::ipc {
namespace {

// Shared (not FUTEX_PRIVATE) futexes: the word lives in memory mapped by several processes.
long futex(std::atomic<uint32_t>* word, int op, uint32_t value, const timespec* timeout) {
  return syscall(SYS_futex, reinterpret_cast<uint32_t*>(word), op, value, timeout, nullptr, 0);
}

}  // namespace

void Doorbell::sleep(uint32_t seen, int64_t timeoutNs) {
  sleepers.fetch_add(1, std::memory_order_seq_cst);
  // Re-check after announcing ourselves: a ring() between prepare() and here is not lost,
  // because ring() increments the sequence before it reads the sleeper count.
  if (sequence.load(std::memory_order_seq_cst) == seen) {
    if (timeoutNs < 0) {
      futex(&sequence, FUTEX_WAIT, seen, nullptr);
    } else {
      timespec ts{static_cast<time_t>(timeoutNs / 1'000'000'000),
                  static_cast<long>(timeoutNs % 1'000'000'000)};
      futex(&sequence, FUTEX_WAIT, seen, &ts);
    }
  }
  sleepers.fetch_sub(1, std::memory_order_seq_cst);
}

bool Doorbell::spin(uint32_t seen, int64_t spinNs) const {
  using Clock = std::chrono::steady_clock;
  const auto until = Clock::now() + std::chrono::nanoseconds(spinNs);
  for (;;) {
    // Look at the clock only every few rounds: reading it costs more than a look at the word.
    for (int i = 0; i < 64; ++i) {
      if (sequence.load(std::memory_order_acquire) != seen) return true;
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#elif defined(__aarch64__)
      asm volatile("yield" ::: "memory");
#endif
    }
    if (Clock::now() >= until) return sequence.load(std::memory_order_seq_cst) != seen;
  }
}

void Doorbell::ring() {
  sequence.fetch_add(1, std::memory_order_seq_cst);
  if (sleepers.load(std::memory_order_seq_cst) != 0) futex(&sequence, FUTEX_WAKE, INT_MAX, nullptr);
}

}  // namespace vrflow::ipc
