#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <atomic>
#include <cstdint>
#include <string_view>

#include "vrflow/base/result.hpp"
#include "vrflow/ipc/module_slot.hpp"
#include "vrflow/ipc/ring.hpp"
#include "vrflow/ipc/segment.hpp"

namespace vrflow::ipc {

/// What a module process may do with its slot of the control table: read what the daemon set
/// up (ports, limits, parameters), put messages on its output rings, take them from its input
/// rings, and report its state and timings. The only module-side code that touches ModuleSlot.
class ModuleSlotUser {
 public:
  /// How take() ended.
  enum class Take { Message, RunStopped, Unneeded, EndOfInput };

  ModuleSlotUser() = default;
  /// The slot `index` of the control table in `segment`; an error when the segment has no
  /// table (yet) or the index is out of range.
  static Result<ModuleSlotUser> join(Segment& segment, long index);

  /// True once join() succeeded.
  bool joined() const { return slot_ != nullptr; }
  /// The module's id in the application (as the daemon wrote it).
  std::string_view id() const { return slot_->id; }
  /// The high 32 bits of the module's object ids (msg::idPrefixes).
  uint32_t idPrefix() const { return slot_->idPrefix; }
  /// Ports of the module, in manifest order.
  int portCount() const { return static_cast<int>(slot_->portCount); }
  std::string_view portName(int port) const { return slot_->ports[port].name; }
  bool portIsInput(int port) const { return slot_->ports[port].isInput != 0; }
  bool portConnected(int port) const { return slot_->ports[port].connected != 0; }
  /// The index of the input (or output) port `name`; -1 when the manifest has none.
  int findPort(std::string_view name, bool input) const;

  /// The module's iteration count (--iterations); 0: no limit.
  uint64_t iterationLimit() const { return slot_->iterationLimit; }
  /// True when endIt leaves as wait() returns (FlowVR's timing) rather than at the next wait().
  bool endItAfterWait() const { return slot_->endItAfterWait != 0; }
  /// The "name=value\n" text of the module's parameters.
  std::string_view paramsBlock() const;
  /// The module's trace ring when the run is traced; null otherwise.
  TraceRing* traceRing() const;

  /// True once the run asked every module to stop.
  bool stopRequested() const {
    return segment_->header().stopRequested.load(std::memory_order_acquire) != 0;
  }
  /// True once the daemon found that nothing needs this module's outputs any more.
  bool unneeded() const { return slot_->unneeded.load(std::memory_order_acquire) != 0; }

  /// Says what the module is doing (and on which port, while waiting or putting).
  void setState(ModuleState state, int port = -1) {
    slot_->waitingPort.store(port, std::memory_order_relaxed);
    slot_->state.store(static_cast<uint32_t>(state), std::memory_order_release);
  }
  /// Records the process that joined (the supervisor samples and signals it).
  void setPid(int32_t pid) { slot_->pid.store(pid); }
  /// Says that an allocation of the module failed (async-signal-safe: one atomic store).
  void markOutOfMemory() { slot_->outOfMemory.store(1); }
  /// Adds one iteration's compute time (total and histogram).
  void addCompute(uint64_t ns) {
    slot_->computeNs.fetch_add(ns, std::memory_order_relaxed);
    slot_->histogram[histogramBucket(ns)].fetch_add(1, std::memory_order_relaxed);
  }
  /// Adds time spent waiting for inputs.
  void addWait(uint64_t ns) { slot_->waitNs.fetch_add(ns, std::memory_order_relaxed); }
  /// Publishes how many iterations the module has completed.
  void setIterations(uint64_t count) { slot_->iterations.store(count, std::memory_order_release); }
  /// The module ends for `cause`: recorded once, the state becomes Finished, the daemon wakes.
  void finish(EndCause cause) {
    slot_->endCause.store(static_cast<uint32_t>(cause), std::memory_order_release);
    setState(ModuleState::Finished);
    segment_->header().daemonBell.ring();
  }

  /// Puts the block `handle` (one reference, handed over) on output `port`, sleeping while its
  /// ring is full; false, with the reference still the caller's, when the run stops meanwhile.
  bool put(int port, uint64_t handle, int64_t pollNs) {
    PortSlot& slot = slot_->ports[port];
    Ring& out = ring(port);
    // Read before the push: from then on the daemon holds the block and may free it.
    const uint64_t bytes = segment_->block(handle).used;
    segment_->handOver(handle);
    setState(ModuleState::Putting, port);
    while (!out.push(handle)) {
      const uint32_t seen = slot_->bell.prepare();
      if (stopRequested()) return false;
      // Ask the daemon to ring once it drains this ring, then look again: it may have drained
      // it before it could see the request (ModuleSlotDaemon::outputDrained).
      slot.wantsSpace.store(1, std::memory_order_seq_cst);
      std::atomic_thread_fence(std::memory_order_seq_cst);
      if (out.push(handle)) break;
      slot_->bell.sleep(seen, pollNs);
    }
    slot.messages.fetch_add(1, std::memory_order_relaxed);
    slot.bytes.fetch_add(bytes, std::memory_order_relaxed);
    segment_->header().daemonBell.ring();
    return true;
  }

  /// Takes the next block from input `port` into `handle` (one reference, now the caller's),
  /// sleeping until one comes; or says why none ever will (the run stops, the module is
  /// unneeded, every producer of the input ended).
  Take take(int port, uint64_t& handle, int64_t pollNs) {
    PortSlot& slot = slot_->ports[port];
    Ring& in = ring(port);
    setState(ModuleState::Waiting, port);
    // The opt-in spin, once per take(): bounded, then the module sleeps as usual.
    int64_t spinNs = segment_->header().spinNs;
    for (;;) {
      const uint32_t seen = slot_->bell.prepare();
      if (stopRequested()) return Take::RunStopped;
      if (unneeded()) return Take::Unneeded;
      if (in.pop(handle)) break;
      if (slot.closed.load(std::memory_order_acquire) != 0 && in.empty()) return Take::EndOfInput;
      if (spinNs > 0) {
        const bool rung = slot_->bell.spin(seen, spinNs);
        spinNs = 0;
        if (rung) continue;
      }
      slot_->bell.sleep(seen, pollNs);
    }
    // Room freed on this ring: wake the daemon only if it is waiting for it.
    std::atomic_thread_fence(std::memory_order_seq_cst);
    if (slot.wantsSpace.load(std::memory_order_seq_cst) != 0 && slot.wantsSpace.exchange(0) != 0) {
      segment_->header().daemonBell.ring();
    }
    return Take::Message;
  }

 private:
  ModuleSlotUser(Segment& segment, ModuleSlot& slot) : segment_(&segment), slot_(&slot) {}
  Ring& ring(int port) const { return *segment_->at<Ring>(slot_->ports[port].ringOffset); }

  Segment* segment_ = nullptr;
  ModuleSlot* slot_ = nullptr;
};

}  // namespace vrflow::ipc
