// The MPI peer, launcher side: runs this same binary as two ranks under mpirun and collects the
// JSON lines rank 0 prints (see mpi_rank.cpp for the measurement itself).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "transport_bench.hpp"

namespace vrflow::bench {

namespace {

constexpr const char* kTransport = "mpi-shm";
constexpr std::chrono::milliseconds kExitTimeout{10'000};

std::string joinSizes(const std::vector<std::size_t>& sizes) {
  std::string text;
  for (const std::size_t bytes : sizes) {
    if (!text.empty()) {
      text += ',';
    }
    text += std::to_string(bytes);
  }
  return text;
}

Error failure(const std::string& message) {
  return makeError(std::string(kTransport) + ": " + message);
}

}  // namespace

Result<std::vector<BenchResult>> runMpi(const char* selfPath, const BenchSettings& settings) {
  const auto mpirun = findInPath("mpirun");
  if (!mpirun) {
    return failure(
        "mpirun not found in PATH; install Open MPI (Debian: apt-get install openmpi-bin)");
  }
  // Shared memory only: ob1 over vader (and self for a rank talking to itself). Given on the
  // command line, these override any OMPI_MCA_pml / OMPI_MCA_btl in the environment; TCP, UCX and
  // the network BTLs cannot be picked. Open MPI's default binding (one core per rank for
  // -np 2) applies; rank 0 reports its affinity in `detail`.
  std::vector<std::string> argv = {*mpirun, "-np", "2", "--oversubscribe"};
  if (geteuid() == 0) {
    argv.emplace_back("--allow-run-as-root");
  }
  for (const char* argument : {"--mca", "pml", "ob1", "--mca", "btl", "self,vader"}) {
    argv.emplace_back(argument);
  }
  for (const std::string& argument : {std::string(selfPath), std::string("--mpi-rank-mode"),
                                      std::string("--sizes"), joinSizes(settings.sizes)}) {
    argv.push_back(argument);
  }
  if (settings.quick) {
    argv.emplace_back("--quick");
  }

  auto launcher = ChildProcess::spawn(argv);
  if (!launcher) {
    return failure(launcher.error().message);
  }
  std::vector<BenchResult> results;
  while (true) {
    // Between two sizes a healthy run prints within the peer timeout; silence means a hang.
    auto line = launcher->readLine(settings.peerTimeout);
    if (!line) {
      launcher->terminate();
      return failure("mpirun: " + line.error().message + "; stopped it");
    }
    if (!*line) {
      break;
    }
    auto result = parseJsonLine(**line);
    if (result && result->transport == kTransport) {
      results.push_back(*result);
    } else {
      std::fprintf(stderr, "%s\n", (*line)->c_str());  // mpirun's own messages
    }
  }
  const auto status = launcher->wait(kExitTimeout);
  if (!status) {
    return failure("mpirun " + status.error().message);
  }
  if (*status != 0) {
    return failure("mpirun " + ChildProcess::describeExit(*status) + " (see its messages above)");
  }
  if (results.size() != settings.sizes.size()) {
    return failure("expected " + std::to_string(settings.sizes.size()) +
                   " results from rank 0, got " + std::to_string(results.size()));
  }
  return results;
}

}  // namespace vrflow::bench
