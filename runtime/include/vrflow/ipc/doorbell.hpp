#pragma once

#include <atomic>
#include <cstdint>

namespace vrflow::ipc {

/// An event count in shared memory: a process sleeps on it (futex, no spinning) until another
/// rings it. Ringing costs one atomic add and, only when someone sleeps, one futex wake.
struct Doorbell {
  std::atomic<uint32_t> sequence{0};
  std::atomic<uint32_t> sleepers{0};

  /// The value to pass to sleep(); read it before checking the condition you wait for.
  uint32_t prepare() const { return sequence.load(std::memory_order_seq_cst); }

  /// Sleeps until rung after prepare() returned `seen`, or until timeoutNs passes (< 0: no limit).
  void sleep(uint32_t seen, int64_t timeoutNs = -1);

  /// Wakes every sleeper.
  void ring();

  /// Busy-waits up to spinNs for a ring after prepare() returned `seen`, without sleeping; true
  /// when it was rung meanwhile. The opt-in spin before sleep() (VRFLOW_SPIN_US,
  /// docs/shared-memory.md): it saves the futex wake-up when the ringer comes soon, at the cost
  /// of a busy core while it lasts.
  bool spin(uint32_t seen, int64_t spinNs) const;
};

static_assert(std::atomic<uint32_t>::is_always_lock_free);

}  // namespace vrflow::ipc
