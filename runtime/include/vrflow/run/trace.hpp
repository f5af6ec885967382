#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstdint>
#include <string>
#include <vector>

#include "vrflow/app/model.hpp"
#include "vrflow/base/result.hpp"
#include "vrflow/ipc/control.hpp"

// `--trace FILE.json`: what modules record (ipc::TraceRing), gathered per host, and written in
// the Chrome / Perfetto trace-event format.
namespace vrflow::run {

/// The trace events of one host, in that host's steady clock.
struct HostTrace {
  std::string host;
  int64_t clockOffsetNs = 0;         ///< this host's steady clock minus the reference clock
  std::vector<std::string> modules;  ///< module ids; Event::module indexes this
  struct Event {
    uint32_t module = 0;
    ipc::TraceEvent event;
  };
  std::vector<Event> events;
  std::vector<ipc::TraceMerge> merges;  ///< the parts of the messages this host's filters merged
  uint64_t dropped = 0;                 ///< events lost to full rings or to the per-host cap
};

/// At most this many events are kept per host (the rest are counted in `dropped`).
inline constexpr std::size_t kMaxTraceEventsPerHost = 2'000'000;

/// Moves what `ring` holds into `trace` (as events of module `module`).
void drainTraceRing(ipc::TraceRing& ring, uint32_t module, HostTrace& trace);

/// One host's trace as compact JSON (sent by a daemon to the launcher), and back.
std::string hostTraceToJson(const HostTrace& trace);
Result<HostTrace> hostTraceFromJson(const std::string& text);

/// The Chrome trace-event JSON of every host: one process per host, one thread per module,
/// "wait" and "compute" spans, each message a flow from its sender's put to its receiver's
/// wait; clocks aligned by each host's clockOffsetNs. A flow starts when the put starts, so it
/// never ends before it starts on one host; a merged message has a flow per part; a message a
/// module forwards unchanged is a hop of its own (from the forwarding module).
std::string chromeTrace(const app::Application& application, const std::vector<HostTrace>& hosts);

}  // namespace vrflow::run
