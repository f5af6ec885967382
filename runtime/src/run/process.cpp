#include "vrflow/run/process.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>

extern char** environ;

namespace vrflow::run {
namespace {

// `name` as exec would find it: itself when it holds a '/', else the first executable of that
// name in a folder of $PATH (or `name` itself when there is none).
std::string resolveExecutable(const std::string& name) {
  if (name.find('/') != std::string::npos) return name;
  const char* searchPath = std::getenv("PATH");
  const std::string dirs = searchPath ? searchPath : "/usr/local/bin:/usr/bin:/bin";
  for (std::size_t start = 0; start <= dirs.size();) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string candidate = dirs.substr(start, end - start) + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return name;
}

// Writes `text` on stderr from a forked child (async-signal-safe).
void say(const std::string& text) {
  (void)!write(STDERR_FILENO, text.data(), text.size());
}

}  // namespace

Result<pid_t> spawnProcess(const ProcessSettings& settings) {
  if (settings.argv.empty()) return makeError("no program to start");
  const std::string& executable = settings.argv.front();
  const std::string path = resolveExecutable(executable);
  if (access(path.c_str(), X_OK) != 0) {
    return makeError("cannot start '" + executable + "': " + std::strerror(errno));
  }
  // Everything the child needs is prepared before fork: after it, only async-signal-safe calls.
  std::vector<std::string> envStrings = settings.environment;
  std::vector<char*> envp;
  for (auto& e : envStrings) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::vector<std::string> argStrings = settings.argv;
  argStrings.front() = path;
  std::vector<char*> argv;
  for (auto& a : argStrings) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string limitFailed =
      "vrflow: cannot set the memory limit (RLIMIT_DATA) of " + executable + "\n";
  const std::string execFailed = "vrflow: exec of " + executable + " failed\n";
  const pid_t parent = getpid();

  const pid_t pid = fork();
  if (pid < 0) return makeError(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the parent died before we set the death signal
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGPIPE, SIG_DFL);
    if (settings.stdinFd >= 0) dup2(settings.stdinFd, STDIN_FILENO);
    if (settings.stdoutFd >= 0) dup2(settings.stdoutFd, STDOUT_FILENO);
    if (settings.stderrFd >= 0) dup2(settings.stderrFd, STDERR_FILENO);
    // Nothing else this process holds reaches the child (log files, pipes of other modules,
    // descriptors inherited without close-on-exec from whoever started vrflow).
    close_range(3, ~0U, CLOSE_RANGE_CLOEXEC);
    if (settings.inheritFd >= 0) fcntl(settings.inheritFd, F_SETFD, 0);
    if (settings.memoryLimitBytes > 0) {
      const rlimit limit{settings.memoryLimitBytes, settings.memoryLimitBytes};
      if (setrlimit(RLIMIT_DATA, &limit) != 0) {
        say(limitFailed);
        _exit(127);
      }
    }
    execve(argv[0], argv.data(), envp.data());
    say(execFailed);
    _exit(127);
  }
  setpgid(pid, pid);  // also from the parent, so there is no window where it is unset
  return pid;
}

std::vector<std::string> environmentWith(const std::vector<std::string>& extra) {
  auto nameOf = [](const std::string& entry) { return entry.substr(0, entry.find('=')); };
  std::vector<std::string> names;
  for (const auto& e : extra) names.push_back(nameOf(e));
  std::vector<std::string> environment;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    if (std::find(names.begin(), names.end(), nameOf(entry)) != names.end()) continue;
    environment.push_back(entry);
  }
  environment.insert(environment.end(), extra.begin(), extra.end());
  return environment;
}

}  // namespace vrflow::run
