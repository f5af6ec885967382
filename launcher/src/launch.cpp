#include "vrflow/launcher/launch.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "monitor_files.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/net/control.hpp"
#include "vrflow/net/transport.hpp"
#include "vrflow/run/process.hpp"
#include "vrflow/run/trace.hpp"

namespace vrflow::launcher {
namespace {

using Clock = std::chrono::steady_clock;

// A daemon answers "stop" with "stopping" from its control reader at once; one that has not
// within this time (frozen, stopped by a signal, swapping) is killed.
constexpr double kStopAnswerSeconds = 0.5;
// A daemon that answered must then exit within this time, or it is killed too.
constexpr double kStopExitSeconds = 8;

int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string describeStatus(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    return "was killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  }
  return "ended";
}

// One host's daemon, as the launcher sees it.
struct HostDaemon {
  int index = 0;
  std::string host, bind;
  pid_t pid = -1;
  int toDaemon = -1, fromDaemon = -1;
  std::string buffer;
  int port = -1;
  bool viaSsh = false;
  bool viaMpirun = false;
  bool connected = false, finished = false, exited = false;
  bool stopAnswered = false;  ///< it answered "stop"
  int finishedCode = 0;
  std::string finishedStatus, finishedError, report, exitText, trace;
  std::string stats, previousStats;  ///< the last two "stats" lines (vrflow monitor)
  bool clockKnown = false;
  int64_t clockOffsetNs = 0;  ///< the daemon's steady clock minus ours

  void send(const net::ControlCommand& command) const {
    if (toDaemon < 0) return;
    const std::string text = net::toLine(command) + "\n";
    [[maybe_unused]] auto n = write(toDaemon, text.data(), text.size());
  }
  std::string name() const {
    return "daemon of host '" + host + "' (" + bind +
           (viaSsh      ? ", ssh pid "
            : viaMpirun ? ", mpirun pid "
                        : ", pid ") +
           std::to_string(pid) + ")";
  }
};

// One word for a POSIX shell: single-quoted, with ' written as '\''.
std::string shellQuote(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

// Starts a daemon (or ssh, or mpirun) with a pipe on its standard input and one on its
// standard output (the control channel), or stderr as its output when `stdoutToStderr`.
Result<pid_t> spawnDaemon(const std::vector<std::string>& argv,
                          const std::vector<std::string>& environment, int& toChild, int& fromChild,
                          bool stdoutToStderr = false) {
  int in[2], out[2];
  if (pipe2(in, O_CLOEXEC) != 0) return makeError(std::string("pipe: ") + std::strerror(errno));
  if (pipe2(out, O_CLOEXEC) != 0) {
    const int err = errno;
    close(in[0]);
    close(in[1]);
    return makeError(std::string("pipe: ") + std::strerror(err));
  }
  run::ProcessSettings settings;
  settings.argv = argv;
  settings.environment = run::environmentWith(environment);
  settings.stdinFd = in[0];
  settings.stdoutFd = stdoutToStderr ? STDERR_FILENO : out[1];
  auto pid = run::spawnProcess(settings);
  close(in[0]);
  close(out[1]);
  if (!pid) {
    close(in[1]);
    close(out[0]);
    return pid.error();
  }
  toChild = in[1];
  fromChild = out[0];
  fcntl(fromChild, F_SETFL, fcntl(fromChild, F_GETFL) | O_NONBLOCK);
  return *pid;
}

class Launcher {
 public:
  Launcher(const app::Application& application, const LaunchOptions& options)
      : application_(application), options_(options) {}
  run::RunOutcome run();

 private:
  Status start();
  Status startMpirun(const std::string& daemonPath, const net::Secret& secret);
  // The options every daemon gets, whatever the backend: trace, peer timeout, iterations and
  // search paths (made absolute).
  void appendDaemonOptions(std::vector<std::string>& argv) const;
  void pump(int timeoutMs);
  void onLine(HostDaemon& d, const std::string& line);
  void failWith(run::RunOutcome outcome, bool rootCause);
  void stopAll();
  void publish();
  Clock::time_point lastPublish_{};
  std::optional<std::string> monitorDir_;  ///< where publish() writes; unset: not yet chosen
  bool allExited() const {
    for (const auto& d : daemons_) {
      if (!d.exited) return false;
    }
    return true;
  }

  const app::Application& application_;
  const LaunchOptions& options_;
  std::vector<HostDaemon> daemons_;
  int signalFd_ = -1;
  std::optional<run::RunOutcome> failure_;
  bool failureIsRoot_ = false;
  Clock::time_point failureAt_;
  bool interrupted_ = false;
  bool stopping_ = false;
};

void Launcher::failWith(run::RunOutcome outcome, bool rootCause) {
  if (stopping_) return;  // what dies while we stop everything is our doing, not a cause
  // A daemon's own death or a module's failure names the cause better than a peer's
  // "lost the link": keep the first root cause.
  if (failure_ && (failureIsRoot_ || !rootCause)) return;
  if (!failure_) failureAt_ = Clock::now();
  // Said when seen: stopping the other hosts takes a moment, and the cause must not wait for it.
  std::fprintf(stderr, "vrflow: %s; stopping every host\n", outcome.error.c_str());
  failure_ = std::move(outcome);
  failureIsRoot_ = rootCause;
}

void Launcher::onLine(HostDaemon& d, const std::string& line) {
  auto parsed = net::parseControlEvent(line);
  if (!parsed) return;  // not a line of the protocol: nothing to act on
  net::ControlEvent& event = *parsed;
  using Kind = net::ControlEvent::Kind;
  switch (event.kind) {
    case Kind::Hello:
      break;  // only on mpirun's control socket, before the channel is the daemon's
    case Kind::Listening:
      d.port = event.port;
      break;
    case Kind::Connected:
      d.connected = true;
      break;
    case Kind::Stopping:
      d.stopAnswered = true;
      break;
    case Kind::Error:
      failWith({run::kExitRunFailed, "failed", "host '" + d.host + "': " + event.text}, true);
      break;
    case Kind::Finished:
      d.finished = true;
      d.finishedCode = event.exitCode;
      d.finishedStatus = event.status;
      d.finishedError = event.text;
      if (d.finishedCode != 0 && d.finishedStatus != "stopped") {
        const bool lostLink = d.finishedError.rfind("lost the link", 0) == 0;
        failWith({d.finishedCode, d.finishedStatus, "host '" + d.host + "': " + d.finishedError},
                 !lostLink);
      }
      break;
    case Kind::Report:
      d.report = std::move(event.text);
      break;
    case Kind::Stats:
      d.previousStats = std::move(d.stats);
      d.stats = std::move(event.text);
      break;
    case Kind::Trace:
      d.trace = std::move(event.text);
      break;
    case Kind::Clock:
      // "clock T0 Td": our send time echoed with the daemon's clock; the daemon read its clock
      // about half-way through the round trip.
      d.clockOffsetNs = event.clockDaemonNs - (event.clockSentNs + steadyNs()) / 2;
      d.clockKnown = true;
      break;
  }
}

void Launcher::pump(int timeoutMs) {
  std::vector<pollfd> fds;
  fds.push_back({signalFd_, POLLIN, 0});
  for (const auto& d : daemons_) fds.push_back({d.fromDaemon, POLLIN, 0});
  poll(fds.data(), fds.size(), timeoutMs);
  if (fds[0].revents & POLLIN) {
    signalfd_siginfo info{};
    while (read(signalFd_, &info, sizeof info) == sizeof info) {
      if ((info.ssi_signo == SIGINT || info.ssi_signo == SIGTERM) && !interrupted_) {
        interrupted_ = true;
        failWith(
            {run::kExitInterrupted, "interrupted",
             std::string("interrupted by ") + (info.ssi_signo == SIGINT ? "SIGINT" : "SIGTERM")},
            true);
      }
    }
  }
  for (std::size_t i = 0; i < daemons_.size(); ++i) {
    HostDaemon& d = daemons_[i];
    if (d.fromDaemon < 0) continue;
    char chunk[65536];
    while (true) {
      const ssize_t n = read(d.fromDaemon, chunk, sizeof chunk);
      if (n > 0) {
        d.buffer.append(chunk, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0) {
        close(d.fromDaemon);
        d.fromDaemon = -1;
        // Under mpirun every daemon has the same process (mpirun): the control channel's end
        // is what names the host that died.
        if (d.viaMpirun && !d.finished) {
          failWith(
              {run::kExitRunFailed, "failed", d.name() + " closed its control channel: it died"},
              true);
        }
      }
      break;
    }
    std::size_t eol = 0;
    while ((eol = d.buffer.find('\n')) != std::string::npos) {
      const std::string line = d.buffer.substr(0, eol);
      d.buffer.erase(0, eol + 1);
      onLine(d, line);
    }
  }
  int status = 0;
  pid_t pid = 0;
  while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
    for (auto& d : daemons_) {
      if (d.pid != pid || d.exited) continue;
      d.exited = true;
      d.exitText = describeStatus(status);
      // Read what it said last (its report, its finish line) before judging.
      if (d.fromDaemon >= 0) {
        char chunk[65536];
        ssize_t n = 0;
        while ((n = read(d.fromDaemon, chunk, sizeof chunk)) > 0) {
          d.buffer.append(chunk, static_cast<std::size_t>(n));
        }
        std::size_t eol = 0;
        while ((eol = d.buffer.find('\n')) != std::string::npos) {
          const std::string line = d.buffer.substr(0, eol);
          d.buffer.erase(0, eol + 1);
          onLine(d, line);
        }
      }
      if (!d.finished) {
        failWith({run::kExitRunFailed, "failed", d.name() + " " + d.exitText}, true);
      } else if (d.report.empty()) {
        // Without its share the merged report would silently lack this host's modules.
        failWith({run::kExitRunFailed, "failed",
                  d.name() + " " + d.exitText + " after its modules finished, without its report"},
                 true);
      }
      if (d.toDaemon >= 0) close(d.toDaemon);
      d.toDaemon = -1;
    }
  }
}

// mpirun: one process starts every daemon (rank i serves host i); each connects back to a
// control socket here and proves it holds the run secret, handed over in mpirun's environment.
void Launcher::appendDaemonOptions(std::vector<std::string>& argv) const {
  std::error_code ec;
  if (!options_.tracePath.empty()) argv.push_back("--trace");
  char timeout[32];
  std::snprintf(timeout, sizeof timeout, "%g", options_.peerTimeoutSeconds);
  argv.insert(argv.end(), {"--peer-timeout", timeout});
  if (options_.iterations > 0)
    argv.insert(argv.end(), {"--iterations", std::to_string(options_.iterations)});
  if (options_.moduleMemoryBytes > 0) {
    argv.insert(argv.end(), {"--module-memory-limit", std::to_string(options_.moduleMemoryBytes)});
  }
  for (const auto& p : options_.packageDirs) {
    argv.insert(argv.end(), {"--packages", std::filesystem::absolute(p, ec).string()});
  }
  for (const auto& c : options_.compositeDirs) {
    argv.insert(argv.end(), {"--composites", std::filesystem::absolute(c, ec).string()});
  }
  // Each daemon reads the file itself: the command line's parameters go with it.
  for (const auto& s : options_.overrides) argv.insert(argv.end(), {"--set", s});
}

Status Launcher::startMpirun(const std::string& daemonPath, const net::Secret& secret) {
  const int listenFd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  if (inet_pton(AF_INET, options_.controlAddress.c_str(), &addr.sin_addr) != 1 ||
      bind(listenFd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      listen(listenFd, 64) != 0) {
    close(listenFd);
    return makeError("cannot listen for the daemons on " + options_.controlAddress + ": " +
                     std::strerror(errno));
  }
  socklen_t len = sizeof addr;
  getsockname(listenFd, reinterpret_cast<sockaddr*>(&addr), &len);
  const std::string control = options_.controlAddress + ":" + std::to_string(ntohs(addr.sin_port));
  const std::size_t n = application_.hosts.size();
  bool loopback = true;
  std::string hostList;
  for (const auto& h : application_.hosts) {
    loopback = loopback && h.address.rfind("127.", 0) == 0;
    hostList += (hostList.empty() ? "" : ",") + h.address;
  }
  std::error_code ec;
  std::vector<std::string> argv{"mpirun", "-np", std::to_string(n), "-x", "VRFLOW_RUN_SECRET"};
  for (const char* name : {"VRFLOW_PACKAGE_PATH", "VRFLOW_COMPOSITE_PATH", "VRFLOW_FILTER_PATH"}) {
    if (std::getenv(name) != nullptr) argv.insert(argv.end(), {"-x", name});
  }
  // Rank i runs on host i: all on this machine when every host is a loopback address.
  argv.insert(argv.end(), {"--host", loopback ? "localhost:" + std::to_string(n) : hostList});
  argv.insert(argv.end(), {daemonPath, std::filesystem::absolute(options_.appFile, ec).string(),
                           "--control-connect", control});
  appendDaemonOptions(argv);
  int toMpirun = -1, fromMpirun = -1;
  auto pid = spawnDaemon(argv, {"VRFLOW_RUN_SECRET=" + net::secretToHex(secret)}, toMpirun,
                         fromMpirun, /*stdoutToStderr=*/true);
  if (!pid) {
    close(listenFd);
    return makeError("mpirun: " + pid.error().message);
  }
  close(toMpirun);
  close(fromMpirun);
  for (std::size_t i = 0; i < n; ++i) {
    HostDaemon d;
    d.index = static_cast<int>(i);
    d.host = application_.hosts[i].id;
    d.bind = application_.hosts[i].address;
    d.pid = *pid;
    d.viaMpirun = true;
    daemons_.push_back(std::move(d));
  }
  const auto begin = Clock::now();
  std::size_t linked = 0;
  while (linked < n && !failure_) {
    if (secondsSince(begin) > options_.startSeconds) {
      close(listenFd);
      return makeError("not every daemon started by mpirun reached the launcher within " +
                       std::to_string(static_cast<int>(options_.startSeconds)) + " s");
    }
    pollfd p{listenFd, POLLIN, 0};
    if (poll(&p, 1, 50) == 1) {
      const int fd = accept4(listenFd, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd < 0) continue;
      const std::string nonce = net::newNonceHex();
      const std::string hello = net::toLine(net::ControlCommand::nonce(nonce)) + "\n";
      [[maybe_unused]] auto w = write(fd, hello.data(), hello.size());
      // Its answer, "hello INDEX PROOF", within 5 s.
      std::string line;
      const auto until = Clock::now() + std::chrono::seconds(5);
      char c = 0;
      while (Clock::now() < until && line.size() < 512) {
        pollfd q{fd, POLLIN, 0};
        if (poll(&q, 1, 100) != 1) continue;
        if (read(fd, &c, 1) != 1 || c == '\n') break;
        line += c;
      }
      const auto answer = net::parseControlEvent(line);
      const int index = answer ? answer->hostIndex : -1;
      if (!answer || answer->kind != net::ControlEvent::Kind::Hello || index < 0 ||
          static_cast<std::size_t>(index) >= n ||
          daemons_[static_cast<std::size_t>(index)].toDaemon >= 0 ||
          answer->text != net::controlProof(secret, index, nonce)) {
        std::fprintf(stderr,
                     "vrflow: refused a control connection that did not prove the run secret\n");
        close(fd);
        continue;
      }
      HostDaemon& d = daemons_[static_cast<std::size_t>(index)];
      d.toDaemon = fd;
      d.fromDaemon = dup(fd);
      fcntl(d.fromDaemon, F_SETFL, fcntl(d.fromDaemon, F_GETFL) | O_NONBLOCK);
      ++linked;
    }
    pump(0);
  }
  close(listenFd);
  if (failure_) return makeError(failure_->error);
  return {};
}

Status Launcher::start() {
  const std::string daemonPath = (executableDir() / "vrflow-daemon").string();
  const bool ssh = options_.backend == "ssh";
  std::vector<HostEntry> entries;
  if (ssh && options_.hostfile.empty()) {
    return makeError("--backend ssh needs --hosts HOSTFILE (where each host is and how to log in)");
  }
  if (!options_.hostfile.empty()) {
    auto read = readHostfile(options_.hostfile, application_);
    if (!read) return read.error();
    entries = *read;
  }
  const net::Secret secret = net::newSecret();
  if (options_.backend == "mpirun") {
    if (auto status = startMpirun(daemonPath, secret); !status) return status;
  }
  for (std::size_t i = 0; i < application_.hosts.size() && options_.backend != "mpirun"; ++i) {
    const app::Host& host = application_.hosts[i];
    HostDaemon d;
    d.index = static_cast<int>(i);
    d.host = host.id;
    // local: every host on its own loopback address, as a cluster would be.
    d.bind = "127.0.0." + std::to_string(i + 1);
    std::vector<std::string> environment;
    const HostEntry* entry = nullptr;
    for (const auto& e : entries) {
      if (e.host != host.id) continue;
      entry = &e;
      if (!e.address.empty()) d.bind = e.address;
      environment = e.environment;
    }
    if (ssh) {
      if (entry == nullptr) {
        return makeError(options_.hostfile + ": error: no line for host '" + host.id +
                         "' (--backend ssh needs one per host)");
      }
      if (entry->address.empty()) d.bind = host.address;
    }
    std::error_code ec;
    const std::string appFile = std::filesystem::absolute(options_.appFile, ec).string();
    std::vector<std::string> argv{
        entry != nullptr && !entry->daemon.empty() ? entry->daemon : daemonPath,
        appFile,
        "--host",
        host.id,
        "--control",
        "--bind",
        d.bind};
    appendDaemonOptions(argv);
    if (ssh) {
      // ssh carries nothing of our environment: the search paths and the hostfile's env go
      // explicitly on the remote command line (the secret does not: it goes on stdin).
      std::string remote =
          "cd " +
          shellQuote(entry->directory.empty() ? std::filesystem::current_path(ec).string()
                                              : entry->directory) +
          " && exec env";
      for (const char* name :
           {"VRFLOW_PACKAGE_PATH", "VRFLOW_COMPOSITE_PATH", "VRFLOW_FILTER_PATH"}) {
        if (const char* value = std::getenv(name))
          remote += " " + shellQuote(std::string(name) + "=" + value);
      }
      for (const auto& e : environment) remote += " " + shellQuote(e);
      for (const auto& a : argv) remote += " " + shellQuote(a);
      std::vector<std::string> sshArgv{"ssh",           "-T", "-o",
                                       "BatchMode=yes", "-p", std::to_string(entry->sshPort)};
      if (!entry->identity.empty()) sshArgv.insert(sshArgv.end(), {"-i", entry->identity});
      for (const auto& o : entry->sshOptions) sshArgv.insert(sshArgv.end(), {"-o", o});
      sshArgv.push_back(entry->user.empty() ? d.bind : entry->user + "@" + d.bind);
      sshArgv.push_back(remote);
      argv = std::move(sshArgv);
      environment.clear();
      d.viaSsh = true;
    }
    auto pid = spawnDaemon(argv, environment, d.toDaemon, d.fromDaemon);
    if (!pid) return makeError("host '" + host.id + "': " + pid.error().message);
    d.pid = *pid;
    // The secret travels on the daemon's stdin: never on a command line or in a file.
    d.send(net::ControlCommand::secret(net::secretToHex(secret)));
    daemons_.push_back(std::move(d));
  }
  auto waitFor = [&](auto done, const char* what) -> Status {
    const auto begin = Clock::now();
    while (!failure_) {
      bool all = true;
      for (const auto& d : daemons_) all = all && done(d);
      if (all) return {};
      if (secondsSince(begin) > options_.startSeconds) {
        std::string late;
        for (const auto& d : daemons_) {
          if (!done(d)) late += (late.empty() ? "" : ", ") + d.name();
        }
        char text[64];
        std::snprintf(text, sizeof text, "%g s", options_.startSeconds);
        return makeError(std::string("not ") + what + " within " + text + ": " + late);
      }
      pump(50);
    }
    return makeError(failure_->error);
  };
  if (auto s = waitFor([](const HostDaemon& d) { return d.port > 0; }, "listening"); !s) return s;
  for (const auto& d : daemons_) {
    for (const auto& peer : daemons_) {
      d.send(net::ControlCommand::peer(peer.index, peer.bind, static_cast<uint16_t>(peer.port)));
    }
    d.send(net::ControlCommand::bare(net::ControlCommand::Kind::Connect));
  }
  if (auto s = waitFor([](const HostDaemon& d) { return d.connected; }, "linked"); !s) return s;
  if (!options_.tracePath.empty()) {
    for (const auto& d : daemons_) d.send(net::ControlCommand::clock(steadyNs()));
    if (auto s = waitFor([](const HostDaemon& d) { return d.clockKnown; }, "clock-aligned"); !s) {
      return s;
    }
  }
  for (const auto& d : daemons_) d.send(net::ControlCommand::bare(net::ControlCommand::Kind::Go));
  return {};
}

// Rewrites this launch's monitor file (atomically: write, then rename).
void Launcher::publish() {
  std::string text = "{\"application\":" + nlohmann::json(application_.name).dump() +
                     ",\"file\":" + nlohmann::json(application_.file).dump() +
                     ",\"launcher_pid\":" + std::to_string(getpid()) + ",\"hosts\":[";
  for (std::size_t i = 0; i < daemons_.size(); ++i) {
    const auto& d = daemons_[i];
    text += (i ? "," : "") + std::string("{\"host\":") + nlohmann::json(d.host).dump() +
            ",\"address\":" + nlohmann::json(d.bind).dump() +
            ",\"daemon_pid\":" + std::to_string(d.pid) +
            ",\"now\":" + (d.stats.empty() ? "null" : d.stats) +
            ",\"before\":" + (d.previousStats.empty() ? "null" : d.previousStats) + "}";
  }
  text += "]}";
  if (!monitorDir_) {
    // Chosen once: a folder that may not be trusted is refused (the launch goes on unseen).
    auto dir = monitorDirectory();
    if (!dir) {
      std::fprintf(stderr, "vrflow: warning: `vrflow monitor` will not show this launch: %s\n",
                   dir.error().message.c_str());
    } else {
      removeStaleMonitorFiles(*dir);
    }
    monitorDir_ = dir ? *dir : std::string();
  }
  if (!monitorDir_->empty()) publishMonitorFile(*monitorDir_, text);
}

void Launcher::stopAll() {
  stopping_ = true;
  for (const auto& d : daemons_) {
    if (!d.exited) d.send(net::ControlCommand::bare(net::ControlCommand::Kind::Stop));
  }
  const auto begin = Clock::now();
  auto allAnswered = [&] {
    for (const auto& d : daemons_) {
      if (!d.exited && !d.stopAnswered) return false;
    }
    return true;
  };
  while (!allAnswered() && secondsSince(begin) < kStopAnswerSeconds) pump(20);
  for (const auto& d : daemons_) {
    if (d.exited || d.stopAnswered) continue;
    std::fprintf(stderr, "vrflow: the %s did not answer \"stop\" within %g s: killed\n",
                 d.name().c_str(), kStopAnswerSeconds);
    kill(-d.pid, SIGKILL);
  }
  while (!allExited() && secondsSince(begin) < kStopExitSeconds) pump(20);
  for (int round = 0; round < 2 && !allExited(); ++round) {
    for (const auto& d : daemons_) {
      if (!d.exited) kill(-d.pid, round == 0 ? SIGTERM : SIGKILL);
    }
    const auto t = Clock::now();
    while (!allExited() && (round == 1 || secondsSince(t) < 2)) pump(20);
  }
  // A daemon killed under mpirun may still be tearing down when mpirun is gone: the launcher is
  // their subreaper (run()), so it leaves only once every descendant has exited (5 s at most).
  const auto t = Clock::now();
  for (;;) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid < 0 || secondsSince(t) >= 5) break;  // ECHILD: nothing is left
    if (pid == 0) usleep(20'000);
  }
}

run::RunOutcome Launcher::run() {
  sigset_t signals, previous;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGCHLD);
  sigprocmask(SIG_BLOCK, &signals, &previous);
  sigset_t wanted;
  sigemptyset(&wanted);
  sigaddset(&wanted, SIGINT);
  sigaddset(&wanted, SIGTERM);
  signalFd_ = signalfd(-1, &wanted, SFD_CLOEXEC | SFD_NONBLOCK);
  // Orphans of the run (the daemons of an mpirun that died) become our children, to be reaped.
  prctl(PR_SET_CHILD_SUBREAPER, 1);
  const auto begin = Clock::now();

  if (auto status = start(); !status) {
    failWith({run::kExitRunFailed, "failed", status.error().message}, true);
  }
  bool quitSent = false;
  while (!allExited()) {
    pump(50);
    if (failure_) {
      // Give a root cause (a dead daemon, a failed module) a moment to show before stopping.
      if (!failureIsRoot_ && secondsSince(failureAt_) < 0.5) continue;
      break;
    }
    if (options_.timeoutSeconds > 0 && secondsSince(begin) > options_.timeoutSeconds) {
      char text[96];
      std::snprintf(text, sizeof text, "timed out after %g s (--timeout)", options_.timeoutSeconds);
      failWith({run::kExitTimeout, "timeout", text}, true);
      break;
    }
    if (secondsSince(lastPublish_) >= 1.0) {
      publish();
      lastPublish_ = Clock::now();
    }
    bool allFinished = true;
    for (const auto& d : daemons_) allFinished = allFinished && d.finished;
    if (allFinished && !quitSent) {
      for (const auto& d : daemons_)
        d.send(net::ControlCommand::bare(net::ControlCommand::Kind::Quit));
      quitSent = true;
    }
  }
  stopAll();
  if (monitorDir_ && !monitorDir_->empty()) removeMonitorFile(*monitorDir_);
  for (auto& d : daemons_) {
    if (d.toDaemon >= 0) close(d.toDaemon);
    if (d.fromDaemon >= 0) close(d.fromDaemon);
  }
  run::RunOutcome outcome = failure_.value_or(run::RunOutcome{});
  if (!options_.reportPath.empty()) {
    std::vector<std::string> parts;
    for (const auto& d : daemons_) {
      if (!d.report.empty()) parts.push_back(d.report);
    }
    std::ofstream out(options_.reportPath);
    out << mergeReports(application_, parts, outcome, options_.iterations, secondsSince(begin))
        << "\n";
    if (!out && outcome.exitCode == run::kExitOk) {
      outcome = {run::kExitRunFailed, "failed",
                 "cannot write the report '" + options_.reportPath + "'"};
    }
  }
  if (!options_.tracePath.empty()) {
    std::vector<run::HostTrace> traces;
    for (const auto& d : daemons_) {
      if (d.trace.empty()) continue;
      auto trace = run::hostTraceFromJson(d.trace);
      if (!trace) continue;
      trace->host = d.host;
      trace->clockOffsetNs = d.clockOffsetNs;
      traces.push_back(std::move(*trace));
    }
    std::ofstream out(options_.tracePath);
    out << run::chromeTrace(application_, traces) << "\n";
    if (!out && outcome.exitCode == run::kExitOk) {
      outcome = {run::kExitRunFailed, "failed",
                 "cannot write the trace '" + options_.tracePath + "'"};
    }
  }
  close(signalFd_);
  timespec zero{0, 0};
  while (sigtimedwait(&signals, nullptr, &zero) > 0) {
  }
  sigprocmask(SIG_SETMASK, &previous, nullptr);
  return outcome;
}

}  // namespace

run::RunOutcome launch(const app::Application& application, const LaunchOptions& options) {
  if (options.backend != "local" && options.backend != "ssh" && options.backend != "mpirun") {
    return {run::kExitInvalid, "failed", "--backend " + options.backend + ": unknown backend"};
  }
  // Mistakes in what the user gave (exit 2, as an invalid application) before anything starts.
  if (options.backend == "ssh" && options.hostfile.empty()) {
    return {run::kExitInvalid, "failed",
            "--backend ssh needs --hosts HOSTFILE (where each host is and how to log in)"};
  }
  if (!options.hostfile.empty()) {
    if (auto read = readHostfile(options.hostfile, application); !read) {
      return {run::kExitInvalid, "failed", read.error().message};
    }
  }
  Launcher launcher(application, options);
  return launcher.run();
}

}  // namespace vrflow::launcher
