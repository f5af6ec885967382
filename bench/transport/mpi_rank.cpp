// The MPI peer, inside one of the two ranks that runMpi starts under mpirun. Rank 0 measures and
// prints one JSON line per size on stdout; rank 1 is the echo / streaming sender.
//
// Copies: each rank allocates its buffers once per size and touches them before timing. With
// ob1 + vader a small message is copied into and out of a shared-memory FIFO; a large one is
// copied once, straight from the sender's buffer into the receiver's, when vader's single-copy
// mechanism (CMA, process_vm_readv) is available: the `detail` field says which one ran.
#include <mpi.h>
#include <sched.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "transport_bench.hpp"

namespace vrflow::bench {

namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kTransport = "mpi-shm";
constexpr int kPingTag = 1;
constexpr int kStreamTag = 2;
constexpr int kAckTag = 3;
// Requests in flight per streaming window, as in OSU's osu_bw; fewer for large messages so the
// receive buffers stay within streamQueueDepth (the same bound as ZeroMQ's high-water mark).
constexpr std::size_t kMaxWindow = 64;

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// A control variable of Open MPI (an MCA parameter) as text, through the MPI tool interface.
std::string readControlVariable(const char* name) {
  int index = 0;
  if (MPI_T_cvar_get_index(name, &index) != MPI_SUCCESS) {
    return "?";
  }
  char varName[256];
  int varNameLength = sizeof varName;
  int verbosity = 0;
  int bind = 0;
  int scope = 0;
  int descriptionLength = 0;
  MPI_Datatype type = MPI_DATATYPE_NULL;
  MPI_T_enum enumeration = MPI_T_ENUM_NULL;
  MPI_T_cvar_get_info(index, varName, &varNameLength, &verbosity, &type, &enumeration, nullptr,
                      &descriptionLength, &bind, &scope);
  MPI_T_cvar_handle handle = MPI_T_CVAR_HANDLE_NULL;
  int count = 0;
  if (MPI_T_cvar_handle_alloc(index, nullptr, &handle, &count) != MPI_SUCCESS) {
    return "?";
  }
  std::string text = "?";
  if (type == MPI_CHAR) {
    std::vector<char> value(static_cast<std::size_t>(std::max(count, 1)) + 1, '\0');
    if (MPI_T_cvar_read(handle, value.data()) == MPI_SUCCESS) {
      text = value.data();
    }
  } else if (type == MPI_INT) {
    int value = 0;
    if (MPI_T_cvar_read(handle, &value) == MPI_SUCCESS) {
      text = std::to_string(value);
      int items = 0;
      char itemName[256];
      if (enumeration != MPI_T_ENUM_NULL &&
          MPI_T_enum_get_info(enumeration, &items, itemName, &varNameLength) == MPI_SUCCESS) {
        for (int i = 0; i < items; ++i) {
          int itemValue = 0;
          int itemNameLength = sizeof itemName;
          if (MPI_T_enum_get_item(enumeration, i, &itemValue, itemName, &itemNameLength) ==
                  MPI_SUCCESS &&
              itemValue == value) {
            text = itemName;
          }
        }
      }
    }
  }
  MPI_T_cvar_handle_free(&handle);
  return text;
}

std::string describeSetup(std::size_t bytes) {
  char version[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(version, &length);
  std::string library(version, static_cast<std::size_t>(length));
  library = library.substr(0, library.find(','));  // "Open MPI v4.1.4"

  std::string detail = library;
  int provided = 0;
  if (MPI_T_init_thread(MPI_THREAD_SINGLE, &provided) == MPI_SUCCESS) {
    // Only these components are allowed (runMpi passes --mca pml ob1 --mca btl self,vader), so
    // the two ranks can only talk through vader's shared memory; read back what the library holds.
    detail += ", pml=" + readControlVariable("pml") + " btl=" + readControlVariable("btl") +
              " single_copy=" + readControlVariable("btl_vader_single_copy_mechanism");
    MPI_T_finalize();
  }
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  if (sched_getaffinity(0, sizeof cpus, &cpus) == 0) {
    detail += ", rank 0 bound to " + std::to_string(CPU_COUNT(&cpus)) + " cpu(s)";
  }
  const std::size_t window = std::min(kMaxWindow, streamQueueDepth(bytes));
  detail += "; Send/Recv ping-pong, Isend/Irecv stream with window " + std::to_string(window) +
            " and an ack per window (osu_bw)";
  return detail;
}

[[noreturn]] void abortRun(const std::string& message) {
  std::fprintf(stderr, "%s: %s\n", kTransport, message.c_str());
  MPI_Abort(MPI_COMM_WORLD, 3);
  std::_Exit(3);
}

// Rank 0: round-trip samples (ns). Rank 1: echoes what it receives. The echo sends back the
// received buffer, as the ZeroMQ echo sends back the received message.
std::vector<std::int64_t> pingPong(int rank, std::vector<unsigned char>& payload,
                                   std::vector<unsigned char>& inbox, const IterationPlan& plan) {
  const int count = static_cast<int>(payload.size());
  const std::size_t rounds = plan.warmupMessages + plan.pingPongs;
  std::vector<std::int64_t> samples;
  samples.reserve(plan.pingPongs);
  for (std::size_t i = 0; i < rounds; ++i) {
    if (rank == 0) {
      const std::int64_t start = nowNs();
      MPI_Send(payload.data(), count, MPI_BYTE, 1, kPingTag, MPI_COMM_WORLD);
      MPI_Recv(inbox.data(), count, MPI_BYTE, 1, kPingTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      const std::int64_t end = nowNs();
      if (i >= plan.warmupMessages) {
        samples.push_back(end - start);
      }
    } else {
      MPI_Recv(inbox.data(), count, MPI_BYTE, 0, kPingTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      MPI_Send(inbox.data(), count, MPI_BYTE, 0, kPingTag, MPI_COMM_WORLD);
    }
  }
  if (rank == 0 && std::memcmp(inbox.data(), payload.data(), payload.size()) != 0) {
    abortRun("the echoed message differs from the one sent");
  }
  return samples;
}

// osu_bw's pattern: rank 1 streams windows of Isend from one buffer; rank 0 posts a window of
// Irecv into separate slots and acknowledges each window with an empty message, which keeps the
// sender at most one window ahead (ZeroMQ's high-water mark plays that part). Without it the
// sender floods rank 0 with unexpected messages, which ob1 buffers and copies once more. Rank 0
// returns messages per second, timed after the warm-up windows, as ZeroMQ's receiver does.
double stream(int rank, std::vector<unsigned char>& payload, std::vector<unsigned char>& inbox,
              const IterationPlan& plan) {
  const std::size_t bytes = payload.size();
  const int count = static_cast<int>(bytes);
  const std::size_t window = std::min(kMaxWindow, streamQueueDepth(bytes));
  const std::size_t warmupWindows = std::max<std::size_t>(1, plan.warmupMessages / window);
  const std::size_t timedWindows = (plan.streamMessages + window - 1) / window;
  std::vector<MPI_Request> requests(window, MPI_REQUEST_NULL);
  std::int64_t start = 0;
  for (std::size_t w = 0; w < warmupWindows + timedWindows; ++w) {
    for (std::size_t j = 0; j < window; ++j) {
      if (rank == 0) {
        MPI_Irecv(inbox.data() + j * bytes, count, MPI_BYTE, 1, kStreamTag, MPI_COMM_WORLD,
                  &requests[j]);
      } else {
        MPI_Isend(payload.data(), count, MPI_BYTE, 0, kStreamTag, MPI_COMM_WORLD, &requests[j]);
      }
    }
    MPI_Waitall(static_cast<int>(window), requests.data(), MPI_STATUSES_IGNORE);
    if (rank == 0) {
      MPI_Send(nullptr, 0, MPI_BYTE, 1, kAckTag, MPI_COMM_WORLD);
    } else {
      MPI_Recv(nullptr, 0, MPI_BYTE, 0, kAckTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
    if (w + 1 == warmupWindows) {
      start = nowNs();
    }
  }
  const std::int64_t end = nowNs();
  if (rank == 0 && std::memcmp(inbox.data(), payload.data(), bytes) != 0) {
    abortRun("a streamed message differs from the one sent");
  }
  return static_cast<double>(timedWindows * window) / (static_cast<double>(end - start) * 1e-9);
}

}  // namespace

int runMpiRank(const BenchSettings& settings) {
  // mpirun is our parent: if it dies, so do we, even while spinning in MPI_Recv.
  const pid_t launcher = getppid();
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != launcher || launcher == 1) {
    return 1;
  }
  MPI_Init(nullptr, nullptr);
  int rank = 0;
  int size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size != 2) {
    if (rank == 0) {
      std::fprintf(stderr, "%s: needs exactly 2 ranks, got %d\n", kTransport, size);
    }
    MPI_Finalize();
    return 2;
  }
  for (const std::size_t bytes : settings.sizes) {
    const IterationPlan plan = iterationPlan(bytes, settings.quick);
    std::vector<unsigned char> payload = makePayload(bytes);
    // Enough receive slots for one streaming window; zero-filled, so touched before timing.
    std::vector<unsigned char> inbox(bytes * std::min(kMaxWindow, streamQueueDepth(bytes)));
    const std::vector<std::int64_t> roundTrips = pingPong(rank, payload, inbox, plan);
    MPI_Barrier(MPI_COMM_WORLD);
    const double rate = stream(rank, payload, inbox, plan);
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank == 0) {
      const std::string line =
          toJsonLine(makeResult(kTransport, bytes, roundTrips, rate, describeSetup(bytes)));
      std::fprintf(stdout, "%s\n", line.c_str());
      std::fflush(stdout);
    }
  }
  MPI_Finalize();
  return 0;
}

}  // namespace vrflow::bench
