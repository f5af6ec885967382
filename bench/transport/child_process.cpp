#include "child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>
#include <utility>

namespace vrflow::bench {

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::chrono::milliseconds kTerminateGrace{3000};
constexpr std::chrono::milliseconds kReapPoll{5};

std::string errnoText(const char* what) {
  return std::string(what) + ": " + std::strerror(errno);
}

// In a child just after fork: die with the parent, and notice if it is already gone.
void dieWithParent(pid_t parent, int signal) {
  prctl(PR_SET_PDEATHSIG, signal);
  if (getppid() != parent) {
    _exit(1);
  }
}

}  // namespace

Result<ChildProcess> ChildProcess::fork(const std::function<int()>& body) {
  // Buffered output would otherwise be written once by each process.
  std::cout.flush();
  std::fflush(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    return makeError(errnoText("fork"));
  }
  if (pid == 0) {
    dieWithParent(parent, SIGKILL);
    int code = 1;
    try {
      code = body();
    } catch (...) {  // NOLINT(bugprone-empty-catch): any escape is a failed child, reported by code
      code = 1;
    }
    _exit(code);
  }
  return ChildProcess(pid, -1);
}

Result<ChildProcess> ChildProcess::spawn(const std::vector<std::string>& argv) {
  if (argv.empty()) {
    return makeError("spawn: empty command line");
  }
  std::vector<char*> args;
  for (const std::string& arg : argv) {
    args.push_back(const_cast<char*>(arg.c_str()));  // NOLINT: execv's signature, not modified
  }
  args.push_back(nullptr);

  int out[2];
  int execError[2];  // the child writes errno here when exec fails; closed by a good exec
  if (pipe2(out, O_CLOEXEC) != 0) {
    return makeError(errnoText("pipe"));
  }
  if (pipe2(execError, O_CLOEXEC) != 0) {
    close(out[0]);
    close(out[1]);
    return makeError(errnoText("pipe"));
  }
  std::cout.flush();
  std::fflush(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    for (int fd : {out[0], out[1], execError[0], execError[1]}) {
      close(fd);
    }
    return makeError(errnoText("fork"));
  }
  if (pid == 0) {
    // SIGTERM, not SIGKILL: mpirun then still stops its own ranks.
    dieWithParent(parent, SIGTERM);
    const int devNull = open("/dev/null", O_RDONLY);
    if (devNull < 0 || dup2(devNull, STDIN_FILENO) < 0 || dup2(out[1], STDOUT_FILENO) < 0) {
      _exit(127);
    }
    execv(args[0], args.data());
    const int error = errno;
    [[maybe_unused]] const ssize_t n = write(execError[1], &error, sizeof error);
    _exit(127);
  }
  close(out[1]);
  close(execError[1]);
  int childErrno = 0;
  ssize_t got = 0;
  do {
    got = read(execError[0], &childErrno, sizeof childErrno);
  } while (got < 0 && errno == EINTR);
  close(execError[0]);
  ChildProcess child(pid, out[0]);
  if (got == static_cast<ssize_t>(sizeof childErrno)) {
    child.terminate();
    return makeError("cannot run " + argv[0] + ": " + std::strerror(childErrno));
  }
  return child;
}

ChildProcess::ChildProcess(ChildProcess&& other) noexcept
    : pid_(std::exchange(other.pid_, -1)),
      stdoutFd_(std::exchange(other.stdoutFd_, -1)),
      waitStatus_(other.waitStatus_),
      pending_(std::move(other.pending_)) {}

ChildProcess& ChildProcess::operator=(ChildProcess&& other) noexcept {
  if (this != &other) {
    release();
    pid_ = std::exchange(other.pid_, -1);
    stdoutFd_ = std::exchange(other.stdoutFd_, -1);
    waitStatus_ = other.waitStatus_;
    pending_ = std::move(other.pending_);
  }
  return *this;
}

ChildProcess::~ChildProcess() {
  release();
}

void ChildProcess::release() {
  if (pid_ > 0) {
    terminate();
  }
  if (stdoutFd_ >= 0) {
    close(stdoutFd_);
    stdoutFd_ = -1;
  }
  pid_ = -1;
}

bool ChildProcess::running() {
  if (pid_ <= 0 || waitStatus_) {
    return false;
  }
  int status = 0;
  pid_t reaped = 0;
  do {
    reaped = waitpid(pid_, &status, WNOHANG);
  } while (reaped < 0 && errno == EINTR);
  if (reaped == 0) {
    return true;
  }
  // reaped < 0 (ECHILD) means someone else reaped it; report it as a failure.
  waitStatus_ = reaped == pid_ ? status : (1 << 8);
  return false;
}

Result<std::optional<std::string>> ChildProcess::readLine(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (true) {
    const std::size_t newline = pending_.find('\n');
    if (newline != std::string::npos) {
      std::string line = pending_.substr(0, newline);
      pending_.erase(0, newline + 1);
      return std::optional<std::string>(std::move(line));
    }
    if (stdoutFd_ < 0) {
      if (pending_.empty()) {
        return std::optional<std::string>();
      }
      return std::optional<std::string>(std::exchange(pending_, {}));
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) {
      return makeError("no output for " + std::to_string(timeout.count() / 1000) + " s");
    }
    pollfd pfd{stdoutFd_, POLLIN, 0};
    const int ready = poll(&pfd, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno != EINTR) {
      return makeError(errnoText("poll"));
    }
    if (ready <= 0) {
      continue;
    }
    char buffer[4096];
    const ssize_t n = read(stdoutFd_, buffer, sizeof buffer);
    if (n > 0) {
      pending_.append(buffer, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      close(stdoutFd_);
      stdoutFd_ = -1;
    }
  }
}

Result<int> ChildProcess::wait(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (running()) {
    if (Clock::now() > deadline) {
      terminate();
      return makeError("did not exit within " + std::to_string(timeout.count() / 1000) +
                       " s and was stopped");
    }
    std::this_thread::sleep_for(kReapPoll);
  }
  return waitStatus_.value_or(1 << 8);
}

void ChildProcess::terminate() {
  if (!running()) {
    return;
  }
  kill(pid_, SIGTERM);
  kill(pid_, SIGCONT);  // a stopped process acts on SIGTERM only once it runs again
  const auto deadline = Clock::now() + kTerminateGrace;
  while (running() && Clock::now() < deadline) {
    std::this_thread::sleep_for(kReapPoll);
  }
  if (running()) {
    kill(pid_, SIGKILL);
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    waitStatus_ = status;
  }
}

std::string ChildProcess::exitDescription() {
  return running() ? std::string("is running") : describeExit(waitStatus_.value_or(1 << 8));
}

std::string ChildProcess::describeExit(int waitStatus) {
  if (WIFEXITED(waitStatus)) {
    return "exited with status " + std::to_string(WEXITSTATUS(waitStatus));
  }
  if (WIFSIGNALED(waitStatus)) {
    return std::string("killed by signal ") + strsignal(WTERMSIG(waitStatus));
  }
  return "ended with wait status " + std::to_string(waitStatus);
}

std::optional<std::string> findInPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0) {
      return candidate;
    }
  }
  return std::nullopt;
}

int threadCount() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Threads:", 0) == 0) {
      return std::atoi(line.c_str() + 8);
    }
  }
  return 0;
}

}  // namespace vrflow::bench
