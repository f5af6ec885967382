#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <atomic>
#include <cstdint>

#include "vrflow/ipc/control.hpp"
#include "vrflow/ipc/doorbell.hpp"

// The data of the shared-memory protocol between a module and its host's daemon: plain structs
// in the segment, written by both processes. Their fields are private: the module reaches them
// only through ModuleSlotUser (module_slot_user.hpp) and the daemon and supervisor only through
// ModuleSlotDaemon (module_slot_daemon.hpp), as iceoryx's PublisherPortData is reached through
// PublisherPortUser and PublisherPortRouDi (docs/shared-memory.md, "Who touches what").
namespace vrflow::ipc {

class ModuleSlotUser;
class ModuleSlotDaemon;
class ControlTableDaemon;

/// One port of a module, shared between the module and the daemon.
class PortSlot {
  friend class ModuleSlotUser;
  friend class ModuleSlotDaemon;

  char name[kNameBytes] = {};
  uint8_t isInput = 0;
  uint8_t connected = 0;
  uint8_t stampsOnly = 0;
  uint8_t pad = 0;
  std::atomic<uint32_t> closed{0};      ///< input: no message will ever come again
  std::atomic<uint32_t> wantsSpace{0};  ///< who waits for room on this ring: input, the daemon;
                                        ///< output, the module
  uint64_t ringOffset = 0;              ///< input: daemon -> module; output: module -> daemon
  std::atomic<uint64_t> messages{0};
  std::atomic<uint64_t> bytes{0};
};

/// One module process, shared between the module and the daemon.
class ModuleSlot {
  friend class ModuleSlotUser;
  friend class ModuleSlotDaemon;
  friend class ControlTableDaemon;

  char id[kNameBytes] = {};
  char host[kNameBytes] = {};
  uint32_t portCount = 0;
  uint32_t idPrefix = 0;  ///< the high 32 bits of the module's object ids (msg::idPrefixes)
  PortSlot ports[kMaxPortsPerModule];
  Doorbell bell;                         ///< the daemon rings it when this module may go on
  std::atomic<uint32_t> state{0};        ///< a ModuleState
  std::atomic<int32_t> waitingPort{-1};  ///< port index while Waiting/Putting
  std::atomic<uint64_t> iterations{0};
  uint64_t iterationLimit = 0;  ///< 0: no limit
  std::atomic<int32_t> pid{0};
  uint64_t paramsOffset = 0;  ///< the typed parameter set (encodeParameters)
  uint32_t paramsBytes = 0;
  std::atomic<uint64_t> computeNs{0};  ///< total time between wait() returning and the next wait()
  std::atomic<uint64_t> waitNs{0};     ///< total time spent in wait()
  std::atomic<uint64_t> histogram[kHistogramBuckets] = {};  ///< iteration durations (ns)
  uint64_t traceOffset = 0;              ///< a TraceRing when the run is traced; 0: not traced
  std::atomic<uint32_t> outOfMemory{0};  ///< set by the module when an allocation failed
  uint32_t endItAfterWait = 0;           ///< 1: endIt leaves as wait() returns (FlowVR)
  std::atomic<uint32_t> unneeded{0};     ///< 1: the daemon asks it to end (EndCause::Unneeded)
  std::atomic<uint32_t> endCause{0};     ///< an EndCause, written once as the module ends
};

/// The run's table of modules, at SegmentHeader::controlOffset.
class ControlTable {
  friend class ModuleSlotUser;
  friend class ControlTableDaemon;

  uint32_t moduleCount = 0;
  uint32_t pad = 0;
  uint64_t modulesOffset = 0;  ///< ModuleSlot[moduleCount]
};

}  // namespace vrflow::ipc
