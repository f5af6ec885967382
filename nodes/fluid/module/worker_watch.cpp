#include "worker_watch.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace vrflow::fluid {
namespace {

// How long a worker's end waits for rank 0 to release the watch before it counts as a death: a
// setup error that every block meets ends the workers a moment before rank 0, which met it too,
// reports it itself.
constexpr int kGraceMs = 2000;

int openPidfd(pid_t pid) {
#ifdef SYS_pidfd_open
  return static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
#else
  (void)pid;
  errno = ENOSYS;
  return -1;
#endif
}

}  // namespace

std::unique_ptr<WorkerWatch> WorkerWatch::start(const std::vector<pid_t>& pids) {
  std::vector<int> pidfds;
  for (const pid_t pid : pids) {
    const int fd = openPidfd(pid);
    if (fd < 0 && errno != ESRCH) {
      std::fprintf(stderr,
                   "vrflow-fluid: warning: cannot watch the spawned blocks (pidfd_open: %s): a "
                   "block that dies leaves the module waiting until vrflow's --timeout\n",
                   std::strerror(errno));
      for (const int open : pidfds) {
        if (open >= 0) close(open);
      }
      return nullptr;
    }
    pidfds.push_back(fd);  // -1: that worker is already gone
  }
  const int releaseFd = eventfd(0, EFD_CLOEXEC);
  if (releaseFd < 0) {
    std::fprintf(stderr, "vrflow-fluid: warning: cannot watch the spawned blocks (eventfd: %s)\n",
                 std::strerror(errno));
    for (const int open : pidfds) {
      if (open >= 0) close(open);
    }
    return nullptr;
  }
  std::unique_ptr<WorkerWatch> watch(new WorkerWatch(std::move(pidfds), pids, releaseFd));
  watch->thread_ = std::thread([w = watch.get()] { w->watch(); });
  return watch;
}

WorkerWatch::WorkerWatch(std::vector<int> pidfds, std::vector<pid_t> pids, int releaseFd)
    : pidfds_(std::move(pidfds)), pids_(std::move(pids)), releaseFd_(releaseFd) {}

WorkerWatch::~WorkerWatch() {
  const std::uint64_t one = 1;
  (void)!write(releaseFd_, &one, sizeof one);
  if (thread_.joinable()) thread_.join();
  close(releaseFd_);
  for (const int fd : pidfds_) {
    if (fd >= 0) close(fd);
  }
}

void WorkerWatch::watch() {
  std::vector<pollfd> fds{{releaseFd_, POLLIN, 0}};
  std::size_t dead = 0;  // the dead worker's block number (1 ... N-1); 0: none yet
  for (std::size_t i = 0; i < pidfds_.size(); ++i) {
    fds.push_back({pidfds_[i], POLLIN, 0});
    if (pidfds_[i] < 0 && dead == 0) dead = i + 1;
  }
  while (dead == 0) {
    if (poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[0].revents != 0) return;  // released
    for (std::size_t i = 1; i < fds.size() && dead == 0; ++i) {
      if (fds[i].revents != 0) dead = i;
    }
  }
  pollfd release{releaseFd_, POLLIN, 0};
  while (poll(&release, 1, kGraceMs) < 0 && errno == EINTR) {
  }
  if (release.revents != 0) return;
  std::fprintf(stderr,
               "vrflow-fluid: MPI block %zu of %zu (pid %d, spawned by the module) ended "
               "unexpectedly; stopping the module\n",
               dead, pids_.size() + 1, static_cast<int>(pids_[dead - 1]));
  _exit(1);  // the main thread may be inside a collective call that never returns
}

}  // namespace vrflow::fluid
