// The floor peer of the local transports (`transport: "wakeup-floor"`): two processes hand
// each other a 64-bit handle through shared memory and wake each other with a futex, using the
// very primitives a vrflow module uses (ipc::Doorbell, ipc::Ring) but with no daemon between
// them. Ping-pong: each side sleeps until the other rings, so every one-way trip is one
// blocking wake-up between two processes: what any local transport that does not spin pays at
// least once. Streaming: the sender pushes handles on a ring while there is room, the receiver
// pops them; a side sleeps only when the ring is full (sender) or empty (receiver).
// The payload is never touched (as vrflow-shm re-sends a block by handle), so the size only
// names the row these numbers are compared with.
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <bit>
#include <chrono>
#include <cstdint>
#include <new>
#include <span>
#include <vector>

#include "child_process.hpp"
#include "transport_bench.hpp"
#include "vrflow/ipc/doorbell.hpp"
#include "vrflow/ipc/ring.hpp"

namespace vrflow::bench {
namespace {

constexpr int64_t kSliceNs = 100'000'000;  // sleepers look at the clock this often

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// What the two processes share (one anonymous MAP_SHARED mapping made before the fork).
struct Shared {
  ipc::Doorbell toPeer;           // the forked peer sleeps on it
  ipc::Doorbell toMain;           // this process sleeps on it
  std::atomic<uint64_t> ball{0};  // ping-pong: odd = main's turn sent, even = peer's reply
  ipc::Ring ring;                 // streaming; its slots follow
};

// An anonymous shared mapping holding a Shared with a ring of `capacity` slots; unmapped with it.
class SharedMapping {
 public:
  explicit SharedMapping(uint32_t capacity)
      : bytes_(sizeof(Shared) + sizeof(uint64_t) * capacity),
        memory_(mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0)) {
    if (memory_ == MAP_FAILED) return;
    shared_ = new (memory_) Shared();
    shared_->ring.init(capacity);
  }
  SharedMapping(const SharedMapping&) = delete;
  SharedMapping& operator=(const SharedMapping&) = delete;
  ~SharedMapping() {
    if (shared_ != nullptr) shared_->~Shared();
    if (memory_ != MAP_FAILED) munmap(memory_, bytes_);
  }
  Shared* get() const { return shared_; }

 private:
  std::size_t bytes_;
  void* memory_;
  Shared* shared_ = nullptr;
};

// Lets this process run on `cpus` only.
bool runOn(std::span<const int> cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) CPU_SET(cpu, &set);
  return sched_setaffinity(0, sizeof set, &set) == 0;
}

// Sleeps on `bell` until `ready()` holds; false when `deadlineNs` passes first (the other side
// is gone or stuck).
template <typename Ready>
bool sleepUntil(ipc::Doorbell& bell, const Ready& ready, int64_t deadlineNs) {
  for (;;) {
    const uint32_t seen = bell.prepare();
    if (ready()) return true;
    if (nowNs() > deadlineNs) return false;
    bell.sleep(seen, kSliceNs);
  }
}

// `crossCores`: the two processes are pinned to two different CPUs, so every wake-up is of a
// process on the other core (an idle one, mostly: the waker sleeps right after); otherwise the
// scheduler places them, and two processes that take turns usually share one core.
Result<BenchResult> floorSize(std::size_t bytes, const BenchSettings& settings, bool crossCores) {
  const char* name = crossCores ? "wakeup-floor-cross" : "wakeup-floor";
  std::vector<int> cpus;
  if (crossCores) {
    cpus = allowedCpus();
    if (cpus.size() < 2)
      return makeError(std::string(name) + ": needs two CPUs this process may use, has " +
                       std::to_string(cpus.size()));
  }
  const IterationPlan plan = iterationPlan(bytes, settings.quick);
  const auto capacity = std::bit_ceil(static_cast<uint32_t>(streamQueueDepth(bytes)));
  SharedMapping mapping(capacity);
  Shared* shared = mapping.get();
  if (shared == nullptr) return makeError(std::string(name) + ": cannot map shared memory");
  const std::size_t rounds = plan.warmupMessages + plan.pingPongs;
  const std::size_t total = plan.warmupMessages + plan.streamMessages;
  const int64_t silence = std::chrono::nanoseconds(settings.peerTimeout).count();

  auto peer = ChildProcess::fork([&] {
    if (crossCores && !runOn(std::span(cpus).subspan(1, 1))) return 5;
    // Echo each ball, then stream `total` handles.
    for (uint64_t i = 0; i < rounds; ++i) {
      const uint64_t sent = 2 * i + 1;
      if (!sleepUntil(
              shared->toPeer, [&] { return shared->ball.load() == sent; }, nowNs() + silence)) {
        return 3;
      }
      shared->ball.store(sent + 1);
      shared->toMain.ring();
    }
    for (uint64_t handle = 1; handle <= total; ++handle) {
      if (!sleepUntil(
              shared->toPeer, [&] { return shared->ring.push(handle); }, nowNs() + silence)) {
        return 4;
      }
      shared->toMain.ring();
    }
    return 0;
  });
  if (!peer) return peer.error();
  // This process on the first CPU for the measurement, its own set again afterwards.
  struct Restore {
    std::vector<int> cpus;
    ~Restore() {
      if (!cpus.empty()) runOn(cpus);
    }
  } restore;
  if (crossCores) {
    restore.cpus = cpus;
    if (!runOn(std::span(cpus).subspan(0, 1)))
      return makeError(std::string(name) + ": cannot pin to CPU " + std::to_string(cpus[0]));
  }

  std::vector<std::int64_t> samples;
  samples.reserve(plan.pingPongs);
  for (uint64_t i = 0; i < rounds; ++i) {
    const uint64_t sent = 2 * i + 1;
    const std::int64_t start = nowNs();
    shared->ball.store(sent);
    shared->toPeer.ring();
    if (!sleepUntil(
            shared->toMain, [&] { return shared->ball.load() == sent + 1; }, start + silence)) {
      return makeError(std::string(name) + ": the peer " + peer->exitDescription() +
                       " during ping-pong");
    }
    if (i >= plan.warmupMessages) samples.push_back(nowNs() - start);
  }
  std::int64_t start = nowNs();
  for (uint64_t expected = 1; expected <= total; ++expected) {
    uint64_t handle = 0;
    if (!sleepUntil(
            shared->toMain, [&] { return shared->ring.pop(handle); }, nowNs() + silence)) {
      return makeError(std::string(name) + ": the peer " + peer->exitDescription() +
                       " during streaming");
    }
    shared->toPeer.ring();
    if (handle != expected) return makeError(std::string(name) + ": a handle arrived out of order");
    if (expected == plan.warmupMessages) start = nowNs();
  }
  const std::int64_t end = nowNs();
  auto status = peer->wait(settings.peerTimeout);
  if (!status) return status.error();
  if (*status != 0)
    return makeError(std::string(name) + ": peer " + ChildProcess::describeExit(*status) +
                     (*status == 5 ? " (could not pin itself to a CPU)" : ""));
  const double rate =
      static_cast<double>(plan.streamMessages) / (static_cast<double>(end - start) * 1e-9);
  return makeResult(
      name, bytes, samples, rate,
      std::string("2 processes (fork), a 64-bit handle through shared memory and a "
                  "blocking futex wake-up per one-way trip (ipc::Doorbell, ipc::Ring; "
                  "no daemon); the payload is not touched") +
          (crossCores ? "; each process pinned to its own CPU (" + std::to_string(cpus[0]) +
                            " and " + std::to_string(cpus[1]) + ")"
                      : ""));
}

}  // namespace

Result<std::vector<BenchResult>> runWakeupFloor(const BenchSettings& settings, bool crossCores) {
  return forEachSize(settings,
                     [&](std::size_t bytes) { return floorSize(bytes, settings, crossCores); });
}

}  // namespace vrflow::bench
