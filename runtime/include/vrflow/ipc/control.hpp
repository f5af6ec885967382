#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <atomic>
#include <cstdint>

#include "vrflow/ipc/doorbell.hpp"

namespace vrflow::ipc {

inline constexpr int kMaxPortsPerModule = 32;
inline constexpr int kNameBytes = 64;
inline constexpr int kHistogramBuckets = 256;

/// What a module is doing, as seen by the daemon (for deadlock reports and monitoring).
enum class ModuleState : uint32_t { Starting = 0, Waiting, Computing, Putting, Finished };

/// Why a module left the run (ModuleSlotDaemon::endCause), for the run report.
enum class EndCause : uint32_t {
  Running = 0,     ///< not ended, or ended without a word (killed, crashed)
  IterationLimit,  ///< wait() returned false at the module's iteration count (--iterations)
  EndOfInput,      ///< wait() returned false: an input ended (every producer of it ended)
  LeftLoop,        ///< the module left its loop by itself (its Module was destroyed)
  RunStopped,      ///< wait() returned false: the run stopped (Ctrl-C, --timeout, an error)
  Unneeded,        ///< wait() returned false: every module its outputs reach has ended
};

/// What a module records when the run is traced (`--trace`), in steady-clock ns.
enum class TraceKind : uint32_t { Wait = 0, Compute = 1, Received = 2, Sent = 3 };

/// One traced event: a span (wait, compute) or an instant (a message received or sent).
struct TraceEvent {
  uint64_t beginNs = 0, endNs = 0;
  uint64_t iteration = 0;        ///< the module's iteration
  uint64_t sourceIteration = 0;  ///< Received, Sent: the message's iteration stamp
  uint32_t kind = 0;             ///< a TraceKind
  uint32_t sourceHash = 0;       ///< Received, Sent: FNV-1a 32 of the message's source module id
};

inline constexpr uint64_t kTraceCapacity = 8192;

/// When the run is traced: one part of a message that a daemon's filter concatenated (merge,
/// gather, an input fed by several connections), so that the trace draws an arrow per part.
/// The merged message carries the stamps (source, iteration) `merged*`; a part those `part*`.
struct TraceMerge {
  uint32_t mergedSourceHash = 0;  ///< FNV-1a 32 of the merged message's source module id
  uint32_t partSourceHash = 0;    ///< FNV-1a 32 of the part's source module id
  uint64_t mergedIteration = 0;
  uint64_t partIteration = 0;
};

/// Single-producer (the module), single-consumer (the supervisor) ring of trace events; a
/// module that finds it full drops the event and counts it.
struct TraceRing {
  std::atomic<uint64_t> head{0}, tail{0}, dropped{0};
  TraceEvent events[kTraceCapacity];
  void record(const TraceEvent& event) {
    const uint64_t h = head.load(std::memory_order_relaxed);
    if (h - tail.load(std::memory_order_acquire) >= kTraceCapacity) {
      dropped.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    events[h % kTraceCapacity] = event;
    head.store(h + 1, std::memory_order_release);
  }
};

/// Bucket of a duration in the log-linear histogram (4 sub-buckets per power of two).
inline int histogramBucket(uint64_t ns) {
  if (ns < 4) return static_cast<int>(ns);
  const int msb = 63 - __builtin_clzll(ns);
  const int sub = static_cast<int>((ns >> (msb - 2)) & 3);
  const int bucket = msb * 4 + sub;
  return bucket < kHistogramBuckets ? bucket : kHistogramBuckets - 1;
}

/// Upper bound (ns) of a histogram bucket.
inline uint64_t histogramUpperNs(int bucket) {
  if (bucket < 4) return static_cast<uint64_t>(bucket);
  const int msb = bucket / 4;
  const uint64_t sub = static_cast<uint64_t>(bucket % 4);
  return (uint64_t{1} << msb) + ((sub + 1) << (msb - 2)) - 1;
}

}  // namespace vrflow::ipc
