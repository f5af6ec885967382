#include "vrflow/daemon/daemon.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <string_view>
#include <thread>

#include "daemon_impl.hpp"

namespace vrflow::daemon {
namespace {

constexpr int64_t kIdleSleepNs = 100'000'000;
// The routing thread's sleep when an I/O thread held the routing lock (and passes for it).
constexpr int64_t kContendedSleepNs = 1'000'000;

uint64_t nowNs() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

}  // namespace

Result<int64_t> spinFromEnvironment() {
  const char* value = std::getenv("VRFLOW_SPIN_US");  // NOLINT(concurrency-mt-unsafe): start-up
  if (value == nullptr || *value == '\0') return int64_t{0};
  const std::string_view text(value);
  int64_t us = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), us);
  if (ec != std::errc{} || end != text.data() + text.size() || us < 0 || us > kMaxSpinNs / 1000) {
    return makeError("VRFLOW_SPIN_US='" + std::string(text) +
                     "': expected a whole number of microseconds from 0 to " +
                     std::to_string(kMaxSpinNs / 1000) + " (0 or unset: no spinning)");
  }
  return us * 1000;
}

Daemon::Daemon() : impl_(std::make_unique<Impl>()) {}

Daemon::~Daemon() {
  shutdown();
}

Result<std::unique_ptr<Daemon>> Daemon::create(const app::Application& application,
                                               const app::Catalog& catalog,
                                               const DaemonOptions& options) {
  std::unique_ptr<Daemon> daemon(new Daemon());
  Impl& d = *daemon->impl_;
  d.options = options;
  auto segment = ipc::Segment::create(options.segmentBytes);
  if (!segment) return segment.error();
  d.segment = std::move(*segment);
  if (options.spinNs > kMaxSpinNs) {
    return makeError("a spin of " + std::to_string(options.spinNs) + " ns is over the limit of " +
                     std::to_string(kMaxSpinNs) + " ns");
  }
  int64_t spinNs = options.spinNs;
  if (spinNs < 0) {
    auto fromEnvironment = spinFromEnvironment();
    if (!fromEnvironment) return fromEnvironment.error();
    spinNs = *fromEnvironment;
  }
  d.segment.header().spinNs = spinNs;  // before any module maps the segment
  d.graph = std::make_unique<Graph>(d.segment);
  d.graph->traceMerges = options.trace;
  if (options.transport != nullptr) {
    options.transport->attachSegment(d.segment);
    // A message from another host is routed by the transport's I/O thread that read it, not
    // handed to the routing thread: one thread hop (a futex wake-up) less per message.
    options.transport->setArrivalCallback([&d] { d.routeArrivals(); });
  }
  if (auto status = d.build(application, catalog); !status) return status.error();
  return daemon;
}

ipc::Segment& Daemon::segment() {
  return impl_->segment;
}
const std::vector<ModuleProcess>& Daemon::modules() const {
  return impl_->modules;
}
ipc::ModuleSlotDaemon Daemon::slot(int index) const {
  return impl_->slots[static_cast<std::size_t>(index)];
}

Status Daemon::start() {
  Impl& d = *impl_;
  for (auto& node : d.graph->nodes) {
    if (auto status = node->filter->start(*node); !status) return status;
    if (const auto& misread = node->params().firstError()) return *misread;
  }
  d.running.store(true);
  d.thread = std::thread([&d] { d.loop(); });
  return {};
}

void Daemon::moduleEnded(int index) {
  impl_->ended[static_cast<std::size_t>(index)].store(true, std::memory_order_release);
  impl_->segment.header().daemonBell.ring();
}

void Daemon::requestStop() {
  Impl& d = *impl_;
  d.segment.header().stopRequested.store(1, std::memory_order_release);
  for (const auto& module : d.modules) d.slots[static_cast<std::size_t>(module.slotIndex)].wake();
  d.segment.header().daemonBell.ring();
}

void Daemon::shutdown() {
  Impl& d = *impl_;
  if (d.running.exchange(false)) {
    d.segment.header().daemonBell.ring();
    d.thread.join();
  }
  if (!d.graph || !d.built) return;
  // Route what the modules sent last (their processes have ended by now), so that the report
  // sees every message that was put.
  std::lock_guard lock(d.routingMutex);  // a transport's I/O thread may still be routing
  while (d.pass()) {
  }
  d.publishWarnings();
  // Drop every message still buffered: in queues, and in the rings of every module.
  for (auto& queue : d.graph->queues) queue.items.clear();
  for (const auto& moduleRings : d.rings) {
    for (const auto& ring : moduleRings) {
      uint64_t handle = 0;
      while (ring.pop(handle)) {
        if (d.segment.validHandle(handle)) d.segment.release(handle);
      }
    }
  }
}

void Daemon::Impl::routeArrivals() {
  auto& bell = segment.header().daemonBell;
  // A few passes at most: the I/O thread also reads frames and sends heartbeats, and local
  // modules that keep producing would keep pass() busy for ever (a peer then sees no heartbeat
  // for its timeout). What is still moving after them is the routing thread's.
  constexpr int kMaxArrivalPasses = 4;
  int passes = 0;
  do {
    std::unique_lock lock(routingMutex, std::try_to_lock);
    if (!lock.owns_lock() || !running.load(std::memory_order_acquire)) {
      bell.ring();  // the routing thread is at it (or the daemon is not routing): it passes again
      return;
    }
    bool settled = false;
    for (; passes < kMaxArrivalPasses && !settled; ++passes) settled = !pass();
    // Unsettled: the rest is the routing thread's. A filter asked for a timer: the routing
    // thread, asleep, must know when to wake.
    const bool ring = !settled || graph->wakeAtNs != 0;
    lock.unlock();
    if (ring) {
      bell.ring();
      return;
    }
    // Against loop(): it stores passWanted, then tries the lock; we let go of the lock, then
    // look at passWanted. One of the two sees the other.
    std::atomic_thread_fence(std::memory_order_seq_cst);
  } while (passWanted.exchange(false));
}

void Daemon::Impl::loop() {
  auto& bell = segment.header().daemonBell;
  uint64_t lastFullCheck = 0;
  uint64_t lastSnapshot = 0;
  while (running.load(std::memory_order_acquire)) {
    const uint32_t seen = bell.prepare();
    std::unique_lock lock(routingMutex, std::try_to_lock);
    if (!lock.owns_lock()) {
      // A transport's I/O thread is routing what arrived (routeArrivals): rather than block on
      // the mutex (a futex wait, and a wake-up when it lets go), ask it to pass again when done.
      passWanted.store(true);
      std::atomic_thread_fence(std::memory_order_seq_cst);
      if (!lock.try_lock()) {
        // Briefly: a filter's timer, or the checks below, are looked at again soon.
        bell.sleep(seen, kContendedSleepNs);
        continue;
      }
      passWanted.store(false);  // this thread passes now
    }
    bool progressed = false;
    while (pass()) progressed = true;
    const uint64_t now = nowNs();
    if (now - lastFullCheck > 100'000'000) {
      checkFullQueues(now);
      markUnneededModules();
      lastFullCheck = now;
    }
    if (now - lastSnapshot > 500'000'000) {
      publishSnapshot();
      lastSnapshot = now;
    }
    publishWarnings();
    if (progressed) continue;
    // Sleep until a message moves, or until the earliest timer a filter asked for.
    int64_t sleepNs = kIdleSleepNs;
    if (graph->wakeAtNs != 0) {
      const uint64_t current = nowNs();
      sleepNs = graph->wakeAtNs <= current
                    ? 0
                    : std::min<int64_t>(sleepNs, static_cast<int64_t>(graph->wakeAtNs - current));
    }
    lock.unlock();
    // The opt-in spin: a message that comes soon is routed without the futex wake-up.
    const int64_t spinNs = segment.header().spinNs;
    if (spinNs > 0 && sleepNs > 0 && bell.spin(seen, std::min(spinNs, sleepNs))) continue;
    if (sleepNs > 0) bell.sleep(seen, sleepNs);
  }
}

// One sweep over sources and filters; true if anything moved.
bool Daemon::Impl::pass() {
  const uint64_t before = graph->operations;
  graph->wakeAtNs = 0;  // filters that still need a timer ask again in process()
  std::size_t buffered = 0;
  for (auto& source : graph->sources) {
    if (source.closed) continue;
    const ipc::ModuleSlotDaemon& slot = slots[static_cast<std::size_t>(source.module)];
    const ipc::RingRef& ring = source.ring;
    bool popped = false;
    uint64_t handle = 0;
    while (source.queue->items.size() < source.queue->capacity && ring.pop(handle)) {
      // A cheap check at the door, so that a bad message is blamed on the module that sent it
      // (receivers check every byte when they read it).
      const char* problem = nullptr;
      if (!segment.validHandle(handle)) {
        problem = "an invalid handle";
      } else if (segment.block(handle).refs.load(std::memory_order_relaxed) == 0) {
        problem = "a message it no longer holds";
      } else {
        const auto total = msg::MessageView::peekTotalSize(segment.bytes(handle));
        if (!total || *total != segment.block(handle).used) problem = "a malformed message";
      }
      if (problem != nullptr) {
        // A module that breaks the protocol has a bug: the run stops, naming it.
        std::lock_guard lock(warningsMutex);
        if (fatal.empty()) {
          fatal = "module '" + modules[static_cast<std::size_t>(source.module)].id + "' sent " +
                  problem + " on output '" +
                  outputNames[static_cast<std::size_t>(source.module)]
                             [static_cast<std::size_t>(source.port)] +
                  "'";
        }
        if (segment.validHandle(handle) && segment.block(handle).refs.load() != 0) {
          segment.release(handle);
        }
        continue;
      }
      source.queue->items.emplace_back(&segment, handle);
      ++source.queue->messages;
      popped = true;
      ++graph->operations;
    }
    if (popped) slot.outputDrained(source.port);  // wakes the module if it waits for room
    const bool moduleDone =
        ended[static_cast<std::size_t>(source.module)].load(std::memory_order_acquire) ||
        slot.finished();
    if (moduleDone && ring.empty()) {
      source.closed = true;
      source.queue->closed = true;
      ++graph->operations;
    }
  }
  for (auto& input : remoteInputs) {
    if (input.queue->closed) continue;
    bool closed = false;
    if (options.transport->receive(input.channel, *input.sink, closed) > 0) ++graph->operations;
    if (closed) {
      input.queue->closed = true;
      ++graph->operations;
    }
  }
  for (auto& node : graph->nodes) {
    if (node->closed) {
      // Nothing will ever consume these: drop them so that producers are not held back.
      for (std::size_t input = 0; input < node->inputs.size(); ++input) {
        Queue* queue = node->inputs[input];
        if (!queue->items.empty()) {
          queue->dropped += queue->items.size();
          node->countDropped(input, queue->items.size(), "filter ended");
          queue->items.clear();
          ++graph->operations;
        }
      }
      continue;
    }
    node->filter->process(*node);
    if (node->filter->exhausted(*node)) {
      node->closed = true;
      for (auto& output : node->outputs) {
        for (auto& sink : output) sink->close();
      }
      ++graph->operations;
    }
    for (auto* queue : node->inputs) buffered += queue->items.size();
  }
  const bool moved = graph->operations != before || buffered != lastBuffered;
  lastBuffered = buffered;
  return moved;
}

}  // namespace vrflow::daemon
