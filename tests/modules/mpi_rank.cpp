// mpitest/rank: one module of an MPI job per rank (its manifest says mpi-job="job"). Each
// iteration it puts one point object whose position is (MPI rank, MPI size, sum of the ranks
// over MPI_COMM_WORLD): a recorder behind each module shows which rank each module id ran as,
// in a job of what size, and that the ranks of the job talk to each other (the sum is an
// MPI_Allreduce). With `crash-at` = k > 0 it kills itself (SIGKILL) at iteration k.
#include <mpi.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

namespace {

int run(int argc, char** argv) {
  using namespace vrflow;
  // Open MPI refuses root unless told (a module alone is an MPI singleton: no mpirun set it),
  // and its output forwarding may write after the run stopped reading.
  std::signal(SIGPIPE, SIG_IGN);
  if (geteuid() == 0) {
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  }
  // A singleton that never spawns needs no Open MPI daemon (orted), which would otherwise
  // outlive the module for a moment.
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  MPI_Init(&argc, &argv);
  int rank = 0;
  int size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Module module;
  auto& out = module.addOutput("out");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "vrflow-mpitest-rank (MPI rank %d of %d): %s\n", rank, size,
                 status.error().message.c_str());
    return 2;  // without MPI_Finalize: mpirun ends the job's other ranks
  }
  // For the log tests: each rank's line goes to its own module's log.
  std::printf("joined as rank %d of %d\n", rank, size);
  std::fflush(stdout);
  const auto crashAt = static_cast<uint64_t>(module.params().getInt("crash-at"));
  const uint64_t point = module.newId();
  const auto& type = msg::pointType();
  for (;;) {
    // The ranks stop together: one whose run ended must not leave the others waiting for it in
    // a collective call.
    const int going = module.wait() ? 1 : 0;
    int allGoing = 0;
    MPI_Allreduce(&going, &allGoing, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (allGoing == 0) break;
    if (crashAt > 0 && module.iteration() == crashAt) std::raise(SIGKILL);
    int sum = 0;
    MPI_Allreduce(&rank, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    auto message = module.newMessage(256);
    message.builder()
        .addObject(point, type,
                   module.iteration() == 0 ? msg::ObjectOp::Add : msg::ObjectOp::Update)
        .set(msg::PointParam::kPosition,
             msg::Vec3{static_cast<double>(rank), static_cast<double>(size),
                       static_cast<double>(sum)});
    if (!module.put(out, std::move(message))) break;
  }
  const int status = module.exitStatus();
  MPI_Finalize();
  return status;
}

}  // namespace

// Ends with _exit once the module is gone: Open MPI's allocations outlive MPI_Finalize (many in
// components it unloads), and LeakSanitizer's check at exit, in the sanitizer tests, would
// report them as this module's leaks. vrflow, whose code these tests exercise, keeps its checks.
int main(int argc, char** argv) {
  const int status = run(argc, argv);
  std::fflush(nullptr);
  _exit(status);
}
