#include "worker_watch.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace vrflow::fluid {
namespace {

// How long the workers have to connect once spawned (they do it before MPI_Init).
constexpr auto kStartBound = std::chrono::seconds(30);
// How long a worker's end waits for rank 0 to release the watch before it counts as a death: a
// setup error that every block meets ends the workers a moment before rank 0, which met it too,
// reports it itself.
constexpr int kGraceMs = 2000;

// An abstract unix socket address: `name` after a NUL byte, nothing in the file system.
sockaddr_un abstractAddress(const std::string& name, socklen_t& length) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::size_t n = std::min(name.size(), sizeof address.sun_path - 1);
  std::memcpy(address.sun_path + 1, name.data(), n);
  length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + n);
  return address;
}

void closeAll(std::initializer_list<int> fds) {
  for (const int fd : fds) {
    if (fd >= 0) close(fd);
  }
}

}  // namespace

std::unique_ptr<WorkerWatch> WorkerWatch::start(int workers) {
  static std::atomic<int> counter{0};
  const std::string name =
      "vrflow-fluid-watch-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
  const int listenFd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int releaseFd = eventfd(0, EFD_CLOEXEC);
  socklen_t length = 0;
  const sockaddr_un address = abstractAddress(name, length);
  if (listenFd < 0 || releaseFd < 0 ||
      bind(listenFd, reinterpret_cast<const sockaddr*>(&address), length) != 0 ||
      listen(listenFd, workers) != 0) {
    std::fprintf(stderr,
                 "vrflow-fluid: warning: cannot watch the spawned blocks (%s): a block that dies "
                 "leaves the module waiting until vrflow's --timeout\n",
                 std::strerror(errno));
    closeAll({listenFd, releaseFd});
    return nullptr;
  }
  std::unique_ptr<WorkerWatch> watch(new WorkerWatch(workers, listenFd, releaseFd, name));
  watch->thread_ = std::thread([w = watch.get()] { w->watch(); });
  return watch;
}

WorkerWatch::WorkerWatch(int workers, int listenFd, int releaseFd, std::string name)
    : workers_(workers), listenFd_(listenFd), releaseFd_(releaseFd), name_(std::move(name)) {}

WorkerWatch::~WorkerWatch() {
  const std::uint64_t one = 1;
  (void)!write(releaseFd_, &one, sizeof one);
  if (thread_.joinable()) thread_.join();
  closeAll({listenFd_, releaseFd_});
}

void WorkerWatch::watch() {
  struct Worker {
    pid_t pid = 0;
    int block = -1;  // until it says
  };
  // fds: [0] release, [1] listening socket (until every worker is in), [2...] the workers.
  std::vector<pollfd> fds{{releaseFd_, POLLIN, 0}, {listenFd_, POLLIN, 0}};
  std::vector<Worker> workers;
  const auto startEnd = std::chrono::steady_clock::now() + kStartBound;
  char why[256] = {};
  while (why[0] == '\0') {
    const bool starting = static_cast<int>(workers.size()) < workers_;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        startEnd - std::chrono::steady_clock::now());
    const int timeout = starting ? static_cast<int>(std::max<long long>(0, left.count())) : -1;
    const int ready = poll(fds.data(), fds.size(), timeout);
    if (ready < 0 && errno != EINTR) return;
    if (fds[0].revents != 0) return;  // released
    if (ready == 0 && starting) {
      std::snprintf(why, sizeof why, "%d of the %d spawned MPI blocks did not start within %lld s",
                    workers_ - static_cast<int>(workers.size()), workers_,
                    static_cast<long long>(kStartBound.count()));
      break;
    }
    if (ready <= 0) continue;
    if (fds[1].fd >= 0 && fds[1].revents != 0) {
      const int fd = accept4(listenFd_, nullptr, nullptr, SOCK_CLOEXEC);
      ucred peer{};
      socklen_t size = sizeof peer;
      if (fd >= 0 && getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &peer, &size) == 0 &&
          peer.uid == getuid()) {
        workers.push_back({peer.pid, -1});
        fds.push_back({fd, POLLIN, 0});
        if (static_cast<int>(workers.size()) == workers_) fds[1].fd = -1;  // all in: no more
      } else if (fd >= 0) {
        close(fd);  // another user's process: not ours to watch
      }
    }
    for (std::size_t i = 2; i < fds.size() && why[0] == '\0'; ++i) {
      if (fds[i].revents == 0) continue;
      Worker& worker = workers[i - 2];
      std::int32_t block = -1;
      const ssize_t n = read(fds[i].fd, &block, sizeof block);
      if (n == static_cast<ssize_t>(sizeof block)) worker.block = block;
      if (n > 0 || (n < 0 && errno == EINTR)) continue;
      if (worker.block > 0) {
        std::snprintf(why, sizeof why,
                      "MPI block %d of %d (pid %d, spawned by the module) ended unexpectedly",
                      worker.block, workers_ + 1, static_cast<int>(worker.pid));
      } else {
        std::snprintf(why, sizeof why,
                      "a spawned MPI block (pid %d) ended while starting (%d blocks)",
                      static_cast<int>(worker.pid), workers_ + 1);
      }
    }
  }
  pollfd release{releaseFd_, POLLIN, 0};
  while (poll(&release, 1, kGraceMs) < 0 && errno == EINTR) {
  }
  if (release.revents != 0) return;
  std::fprintf(stderr, "vrflow-fluid: %s; stopping the module\n", why);
  _exit(1);  // the main thread may be inside an MPI call that never returns
}

int WorkerWatch::join(const std::string& name) {
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  socklen_t length = 0;
  const sockaddr_un address = abstractAddress(name, length);
  if (fd < 0 || connect(fd, reinterpret_cast<const sockaddr*>(&address), length) != 0) {
    std::fprintf(stderr, "vrflow-fluid --block-worker: cannot reach the module's watch '%s': %s\n",
                 name.c_str(), std::strerror(errno));
    closeAll({fd});
    return -1;
  }
  return fd;
}

void WorkerWatch::tellBlock(int socket, int block) {
  const std::int32_t value = block;
  (void)!send(socket, &value, sizeof value, MSG_NOSIGNAL);
}

}  // namespace vrflow::fluid
