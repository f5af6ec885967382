#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"

// The transport benchmark: every transport runs the same workload (same sizes, same iteration
// plan, same statistics) so that their numbers can be compared as ratios on one machine.
namespace vrflow::bench {

/// One measured (transport, message size) point; printed as one JSON line.
struct BenchResult {
  std::string transport;
  std::size_t bytes = 0;
  double oneWayUsMedian = 0.0;
  double oneWayUsP99 = 0.0;
  double msgsPerS = 0.0;
  std::string detail;  ///< How the transport was set up (library version, sockets, BTL/PML, ...).
};

/// The message sizes measured by default: 64 B, 4 KiB, 1 MiB, 16 MiB.
std::vector<std::size_t> benchSizes();

/// Parses a comma-separated size list such as "64,4K,1MiB,16M" (K/M are powers of 1024).
Result<std::vector<std::size_t>> parseSizes(std::string_view text);

/// Settings shared by every transport; the defaults are the full benchmark.
struct BenchSettings {
  std::vector<std::size_t> sizes = benchSizes();
  bool quick = false;  ///< A few iterations per size: a smoke test, not a measurement.
  std::chrono::milliseconds peerTimeout{30'000};  ///< A peer silent this long counts as dead.
};

/// How many messages one size gets. The same plan drives every transport.
struct IterationPlan {
  std::size_t warmupMessages = 0;  ///< Untimed round trips / streamed messages before timing.
  std::size_t pingPongs = 0;       ///< Timed round trips (one latency sample each).
  std::size_t streamMessages = 0;  ///< Timed messages of the one-way streaming phase.
};

/// The plan for one message size; sized so the full benchmark stays well under a minute.
IterationPlan iterationPlan(std::size_t bytes, bool quick);

/// Messages (or MPI receives) that may be queued at the receiver while streaming: about 64 MiB
/// in all, at most 1000 (ZeroMQ's default high-water mark). Shared so both peers buffer alike.
std::size_t streamQueueDepth(std::size_t bytes);

/// A payload of the given size, filled once with a known pattern (byte i is i * 131 + 7).
std::vector<unsigned char> makePayload(std::size_t bytes);

/// Median and 99th percentile of a set of latency samples, in nanoseconds.
struct LatencySummary {
  double medianNs = 0.0;
  double p99Ns = 0.0;
};

/// Median (mean of the two middle samples when even) and nearest-rank 99th percentile.
/// Precondition: samplesNs is not empty.
LatencySummary summarizeLatency(std::vector<std::int64_t> samplesNs);

/// Median of samplesNs (see summarizeLatency).
double medianNs(std::vector<std::int64_t> samplesNs);

/// Nearest-rank 99th percentile of samplesNs (see summarizeLatency).
double p99Ns(std::vector<std::int64_t> samplesNs);

/// Builds a result from round-trip samples: one-way latency is half the round trip.
BenchResult makeResult(std::string transport, std::size_t bytes,
                       const std::vector<std::int64_t>& roundTripNs, double msgsPerS,
                       std::string detail);

/// The result of one size of a run of the vrflow peer (vrflow_bench_module): ping's round trips
/// (ns, one a line) in `rttFile`, the receiver's messages/s in `rateFile`; an error naming
/// `transport` and the size when no round trip was measured.
Result<BenchResult> readPeerResult(const std::string& transport, std::size_t bytes,
                                   const std::string& rttFile, const std::string& rateFile,
                                   std::string detail);

/// Calls `runSize` for each of the settings' sizes, in order, and collects the results; stops at
/// the first error and returns it.
Result<std::vector<BenchResult>> forEachSize(
    const BenchSettings& settings,
    const std::function<Result<BenchResult>(std::size_t bytes)>& runSize);

/// forEachSize, then removes `dir` (the run's temporary folder), also after an error.
Result<std::vector<BenchResult>> runEachSize(
    const BenchSettings& settings, const std::filesystem::path& dir,
    const std::function<Result<BenchResult>(std::size_t bytes)>& runSize);

/// "CPU model, N cores" of this machine, from /proc/cpuinfo and the online CPU count.
std::string machineDescription();

/// The CPUs this process may run on (its affinity mask), in order.
std::vector<int> allowedCpus();

/// The kernel's cpuidle driver ("unknown" when not readable); for `haltpoll` (a KVM guest) with
/// its guest_halt_poll_ns: "haltpoll, guest_halt_poll_ns 0" means idle cores halt at once.
std::string idlePolicy();

/// The result as one JSON object (no trailing newline), with the machine description and its idle
/// policy added.
std::string toJsonLine(const BenchResult& result);

/// Reads back a line written by toJsonLine (used to collect the MPI ranks' results).
Result<BenchResult> parseJsonLine(std::string_view line);

/// The floor of the local transports: a blocking futex wake-up between this process and a forked
/// child per one-way trip (ipc::Doorbell and ipc::Ring, no daemon), as "wakeup-floor". With
/// `crossCores` ("wakeup-floor-cross") the two processes are pinned to two different CPUs of this
/// process's set (an error with fewer than two): every wake-up is then of the other core, which
/// the scheduler's own placement of two processes taking turns usually avoids. Forks: call it
/// while the process has a single thread.
Result<std::vector<BenchResult>> runWakeupFloor(const BenchSettings& settings, bool crossCores);

/// ZeroMQ over ipc:// between this process and a forked child: REQ/REP ping-pong, then PAIR
/// streaming. Forks, so it must be called while the process has a single thread.
Result<std::vector<BenchResult>> runZeromq(const BenchSettings& settings);

/// Open MPI ping-pong and windowed streaming between two ranks on shared memory (ob1 + vader):
/// starts `mpirun -np 2 <selfPath> --mpi-rank-mode ...` and collects rank 0's JSON lines.
Result<std::vector<BenchResult>> runMpi(const char* selfPath, const BenchSettings& settings);

/// The body of one MPI rank (the `--mpi-rank-mode` entry point); returns the exit code.
int runMpiRank(const BenchSettings& settings);

/// ZeroMQ over tcp://127.0.0.1 (TCP_NODELAY is libzmq's default), otherwise as runZeromq.
Result<std::vector<BenchResult>> runZeromqTcp(const BenchSettings& settings);

/// A plain TCP socket pair on loopback between this process and a forked child.
Result<std::vector<BenchResult>> runRawTcp(const BenchSettings& settings);

/// vrflow across two daemons on loopback (`vrflow launch --backend local`, hosts 127.0.0.1/.2).
Result<std::vector<BenchResult>> runVrflowTcp(const BenchSettings& settings);

/// HOOK for the vrflow side (vrflow_peer.cpp): vrflow's shared-memory transport through the
/// per-host daemon, run on the same plan and reported the same way. main treats an empty result
/// as "not implemented yet".
Result<std::vector<BenchResult>> runVrflow(const BenchSettings& settings);

}  // namespace vrflow::bench
