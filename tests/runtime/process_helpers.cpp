#include "process_helpers.hpp"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace vrflow::testing {
namespace {

// Orphans of the commands we run come back to us, so leftovers can be found precisely even
// while other tests run in parallel.
const bool gSubreaper = [] { return prctl(PR_SET_CHILD_SUBREAPER, 1) == 0; }();

}  // namespace

namespace {

// The runs of a test write their default log folders (docs/logs.md) under a state folder of
// the test process, removed when it ends, never under the user's home; a test may set its own.
struct TestStateFolder {
  TempDir dir;
  TestStateFolder() { setenv("XDG_STATE_HOME", dir.path().c_str(), 0); }
};
const TestStateFolder gStateFolder;

}  // namespace

std::string binDir() {
  if (const char* dir = std::getenv("VRFLOW_BIN_DIR")) return dir;
  // The test executables are built into the same folder as the commands they run.
  std::error_code ec;
  return std::filesystem::read_symlink("/proc/self/exe", ec).parent_path().string();
}

std::string sourceDir() {
  if (const char* dir = std::getenv("VRFLOW_SOURCE_DIR")) return dir;
  return VRFLOW_TEST_SOURCE_DIR;
}

CommandResult runCommand(const std::vector<std::string>& argv, double timeoutSeconds,
                         double signalAfterSeconds, int signal) {
  (void)gSubreaper;
  int outPipe[2], errPipe[2];
  if (pipe2(outPipe, O_CLOEXEC) != 0 || pipe2(errPipe, O_CLOEXEC) != 0) return {};
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(outPipe[1], 1);
    dup2(errPipe[1], 2);
    execv(args[0], args.data());
    _exit(127);
  }
  close(outPipe[1]);
  close(errPipe[1]);
  CommandResult result;
  const auto start = std::chrono::steady_clock::now();
  bool signalled = false, killed = false;
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  int open = 2;
  while (open > 0) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (signalAfterSeconds > 0 && !signalled && elapsed >= signalAfterSeconds) {
      kill(pid, signal);
      signalled = true;
    }
    if (!killed && elapsed >= timeoutSeconds) {
      kill(pid, SIGKILL);
      killed = true;
    }
    if (poll(fds, 2, 20) <= 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || (fds[i].revents & (POLLIN | POLLHUP)) == 0) continue;
      char buffer[4096];
      const ssize_t n = read(fds[i].fd, buffer, sizeof buffer);
      if (n <= 0) {
        close(fds[i].fd);
        fds[i].fd = -1;
        --open;
      } else {
        (i == 0 ? result.out : result.err).append(buffer, static_cast<std::size_t>(n));
      }
    }
  }
  int status = 0;
  waitpid(pid, &status, 0);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

CommandResult runVrflow(std::vector<std::string> args, double timeoutSeconds,
                        double signalAfterSeconds, int signal) {
  std::vector<std::string> argv{binDir() + "/vrflow", "--packages", binDir() + "/../test-packages"};
  argv.insert(argv.end(), args.begin(), args.end());
  return runCommand(argv, timeoutSeconds, signalAfterSeconds, signal);
}

std::vector<std::string> leftoverProcesses() {
  std::vector<std::string> left;
  int rounds = 0;
  // Give a dying process group a moment: the runtime has returned, its children are gone or
  // reparented to us by now.
  for (;;) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      std::ifstream cmd("/proc/" + std::to_string(pid) + "/cmdline");
      left.push_back("pid " + std::to_string(pid) + " (reaped)");
      continue;
    }
    if (pid == 0 && ++rounds < 500) {
      // A child is still running: find and kill it.
      bool any = false;
      for (const ProcessInfo& process : processTable()) {
        if (process.parent != getpid()) continue;
        any = true;
        if (process.state == 'Z')
          continue;  // it ended since waitpid() above: the next round reaps it
        std::ifstream cmd("/proc/" + std::to_string(process.pid) + "/cmdline");
        std::string text;
        std::getline(cmd, text, '\0');
        left.push_back(text);
        kill(process.pid, SIGKILL);
      }
      if (!any) usleep(10000);
      continue;
    }
    break;  // ECHILD: no children at all
  }
  return left;
}

int unusedPort(const std::string& address) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  inet_pton(AF_INET, address.c_str(), &addr.sin_addr);
  int port = 0;
  if (fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    socklen_t len = sizeof addr;
    getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    port = ntohs(addr.sin_port);
  }
  if (fd >= 0) close(fd);
  return port;
}

std::vector<ProcessInfo> processTable() {
  std::vector<ProcessInfo> table;
  DIR* proc = opendir("/proc");
  while (dirent* entry = proc ? readdir(proc) : nullptr) {
    const pid_t pid = std::atoi(entry->d_name);
    if (pid <= 0) continue;
    std::ifstream stat("/proc/" + std::string(entry->d_name) + "/stat");
    std::string line;
    std::getline(stat, line);
    // "pid (name) state ppid ...": the name may hold spaces and parentheses.
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close < open) continue;
    ProcessInfo process;
    process.pid = pid;
    process.name = line.substr(open + 1, close - open - 1);
    std::istringstream rest(line.substr(close + 2));
    rest >> process.state >> process.parent;
    if (rest) table.push_back(std::move(process));
  }
  if (proc) closedir(proc);
  return table;
}

std::vector<std::string> vrflowShmEntries() {
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/shm", ec)) {
    const auto name = entry.path().filename().string();
    if (name.find("vrflow") != std::string::npos) found.push_back(name);
  }
  return found;
}

TempDir::TempDir() {
  char pattern[] = "/tmp/vrflow-test-XXXXXX";
  const char* made = mkdtemp(pattern);
  path_ = made ? made : "/tmp";
}

TempDir::~TempDir() {
  std::error_code ec;
  if (path_ != "/tmp") std::filesystem::remove_all(path_, ec);
}

std::string TempDir::write(const std::string& name, const std::string& text) const {
  std::ofstream(file(name)) << text;
  return file(name);
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::vector<std::string> readLines(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::vector<std::string>> readCsvRows(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  const auto lines = readLines(path);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> cells;
    std::stringstream in(lines[i]);
    for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
    rows.push_back(std::move(cells));
  }
  return rows;
}

}  // namespace vrflow::testing
