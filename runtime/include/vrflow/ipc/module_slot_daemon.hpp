#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"
#include "vrflow/ipc/module_slot.hpp"
#include "vrflow/ipc/ring.hpp"
#include "vrflow/ipc/segment.hpp"

namespace vrflow::ipc {

/// What the daemon and the supervisor may do with a module's slot: set it up before the module
/// starts, wake the module, close its inputs, ask it to end, and read what it reports. The only
/// host-side code that touches ModuleSlot. What the module wrote is read defensively (bounded
/// names and port indices): that memory is the module's to scribble on.
class ModuleSlotDaemon {
 public:
  ModuleSlotDaemon() = default;

  /// Set-up, before the module starts: names, the prefix of its object ids (msg::idPrefixes),
  /// limits, timing of endIt.
  void describe(std::string_view id, std::string_view host, uint32_t idPrefix,
                uint64_t iterationLimit, bool endItAfterWait);
  /// Set-up: gives the module a trace ring (`--trace`).
  Status addTraceRing();
  /// Set-up: the module's "name=value\n" parameter text.
  Status setParams(std::string_view bytes);  ///< the encoded parameter set
  /// Set-up: appends a port with a ring of `ringCapacity` (a power of two) handles, and returns
  /// the daemon's view of that ring. At most kMaxPortsPerModule ports.
  Result<RingRef> addPort(std::string_view name, bool isInput, bool stampsOnly, bool connected,
                          uint32_t ringCapacity);

  /// Wakes the module (a message came, room was made, or it must look at its flags).
  void wake() const { slot_->bell.ring(); }
  /// Says that input `port` will never receive another message, and wakes the module.
  void closeInput(int port) const {
    slot_->ports[port].closed.store(1, std::memory_order_release);
    slot_->bell.ring();
  }
  /// Asks the module to ring the daemon's bell when it takes a message from input `port`
  /// (call, then check for room again: it may have taken one before it could see the request).
  void requestSpace(int port) const {
    slot_->ports[port].wantsSpace.store(1, std::memory_order_seq_cst);
    std::atomic_thread_fence(std::memory_order_seq_cst);
  }
  /// Says that the daemon took messages from output `port`: wakes the module only if it sleeps
  /// in put() for room on that ring (most puts find room; waking a module that waits for its
  /// inputs would cost a futex call and a context switch on the latency path for nothing).
  void outputDrained(int port) const {
    std::atomic_thread_fence(std::memory_order_seq_cst);  // the pop before the flag's load
    auto& wants = slot_->ports[port].wantsSpace;
    if (wants.load(std::memory_order_seq_cst) != 0 && wants.exchange(0) != 0) slot_->bell.ring();
  }
  /// True while the module sleeps (or is about to) in put() for room on output `port`.
  bool waitsForRoom(int port) const {
    return slot_->ports[port].wantsSpace.load(std::memory_order_seq_cst) != 0;
  }
  /// How often the module's doorbell was rung (wake-ups, also of a module that was awake).
  uint32_t rings() const { return slot_->bell.prepare(); }
  /// Asks the module to end (EndCause::Unneeded) and wakes it.
  void markUnneeded() const {
    slot_->unneeded.store(1, std::memory_order_release);
    slot_->bell.ring();
  }
  /// True once markUnneeded() was called.
  bool unneeded() const { return slot_->unneeded.load(std::memory_order_relaxed) != 0; }

  /// What the module says it is doing.
  ModuleState state() const {
    return static_cast<ModuleState>(slot_->state.load(std::memory_order_acquire));
  }
  /// True once the module said it has finished.
  bool finished() const { return state() == ModuleState::Finished; }
  /// The port it waits or puts on while Waiting or Putting; -1 when none (or out of range).
  int waitingPort() const;
  /// The name of `port` as the module's memory holds it (bounded).
  std::string portName(int port) const;
  /// Completed iterations.
  uint64_t iterations() const { return slot_->iterations.load(std::memory_order_acquire); }
  /// The iteration count the module was given; 0: no limit.
  uint64_t iterationLimit() const { return slot_->iterationLimit; }
  /// The pid of the process that joined as this module; 0 until it joined.
  int32_t pid() const { return slot_->pid.load(); }
  /// True when the module said an allocation failed.
  bool outOfMemory() const { return slot_->outOfMemory.load() != 0; }
  /// Why the module ended (EndCause::Running while it runs, or when it ended without a word).
  EndCause endCause() const { return static_cast<EndCause>(slot_->endCause.load()); }
  /// Total compute and wait time (ns).
  uint64_t computeNs() const { return slot_->computeNs.load(); }
  uint64_t waitNs() const { return slot_->waitNs.load(); }
  /// Iterations whose duration fell in histogram bucket `bucket` (see histogramBucket()).
  uint64_t histogramCount(int bucket) const { return slot_->histogram[bucket].load(); }
  /// The module's trace ring when the run is traced; null otherwise.
  TraceRing* traceRing() const;

 private:
  friend class ControlTableDaemon;
  ModuleSlotDaemon(Segment& segment, ModuleSlot& slot) : segment_(&segment), slot_(&slot) {}

  Segment* segment_ = nullptr;
  ModuleSlot* slot_ = nullptr;
};

/// The daemon's side of the run's control table: made once per run, before any module starts,
/// and published (SegmentHeader::controlOffset) once every slot is set up.
class ControlTableDaemon {
 public:
  ControlTableDaemon() = default;
  /// Reserves the table and `moduleCount` empty slots in `segment`, and starts the host's
  /// shared id counter above the modules' own id blocks.
  static Result<ControlTableDaemon> create(Segment& segment, uint32_t moduleCount);
  /// The daemon's handle on slot `index`.
  ModuleSlotDaemon slot(int index) const {
    return ModuleSlotDaemon(*segment_, segment_->at<ModuleSlot>(table_->modulesOffset)[index]);
  }
  /// Lets modules join: from now on they find the table.
  void publish() const;

 private:
  Segment* segment_ = nullptr;
  ControlTable* table_ = nullptr;
  uint64_t offset_ = 0;
};

}  // namespace vrflow::ipc
