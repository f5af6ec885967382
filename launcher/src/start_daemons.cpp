// Starting the daemons of a launch, one per host: as local processes, through ssh or srun
// (slurm.cpp), or all at once through mpirun; then linking them (peers, connect, clock, go).
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "launcher.hpp"
#include "vrflow/base/executable_dir.hpp"
#include "vrflow/base/version.hpp"
#include "vrflow/run/process.hpp"

namespace vrflow::launcher::detail {
namespace {

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

}  // namespace

void Launcher::appendDaemonOptions(std::vector<std::string>& argv) const {
  std::error_code ec;
  // Every daemon refuses to serve a launcher of another vrflow (docs/report.md, "Versions").
  argv.insert(argv.end(), {"--launcher-version", std::string(versionText())});
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
  argv.insert(argv.end(), {"--log-level", options_.logLevel});
  // Each daemon reads the file itself: the command line's parameters go with it.
  for (const auto& s : options_.overrides) argv.insert(argv.end(), {"--set", s});
}

// mpirun: one process starts every daemon, one application context per host (rank i serves
// host i) on its machine, with its own --bind and -x NAME=VALUE; each connects back to a control
// socket here and proves it holds the run secret, handed over in mpirun's environment.
Status Launcher::startMpirun(const std::string& daemonPath, const net::Secret& secret,
                             const std::vector<HostEntry>& entries) {
  const std::size_t n = application_.hosts.size();
  // Where each rank runs (`--host`) and binds: the hostfile's machine (node) and address=,
  // else the file's address; a loopback address runs on this machine.
  std::vector<std::string> targets, binds;
  std::vector<std::vector<std::string>> environments(n);
  for (std::size_t i = 0; i < n; ++i) {
    const app::Host& host = application_.hosts[i];
    std::string target = host.address, bind = host.address;
    for (const auto& e : entries) {
      if (e.host != host.id) continue;
      if (!e.node.empty()) {
        auto ip = ipv4Of(e.node);
        if (!ip) {
          return makeError(options_.hostfile + ":" + std::to_string(e.line) + ": error: host '" +
                           host.id + "': " + ip.error().message);
        }
        target = e.node;
        bind = *ip;
      }
      if (!e.address.empty()) {
        if (e.node.empty()) target = e.address;
        bind = e.address;
      }
      environments[i] = e.environment;
    }
    targets.push_back(target.rfind("127.", 0) == 0 ? "localhost" : target);
    binds.push_back(bind);
  }
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
  std::error_code ec;
  std::vector<std::string> argv{"mpirun"};
  argv.insert(argv.end(), options_.mpirunArgs.begin(), options_.mpirunArgs.end());
  for (std::size_t i = 0; i < n; ++i) {
    // Each context names its machine with as many slots as ranks go there.
    const auto slots = std::count(targets.begin(), targets.end(), targets[i]);
    if (i > 0) argv.push_back(":");
    argv.insert(argv.end(), {"-np", "1", "--host", targets[i] + ":" + std::to_string(slots), "-x",
                             "VRFLOW_RUN_SECRET"});
    for (const char* name :
         {"VRFLOW_PACKAGE_PATH", "VRFLOW_COMPOSITE_PATH", "VRFLOW_FILTER_PATH"}) {
      if (std::getenv(name) != nullptr) argv.insert(argv.end(), {"-x", name});
    }
    for (const auto& e : environments[i]) argv.insert(argv.end(), {"-x", e});
    argv.insert(argv.end(),
                {daemonPath, std::filesystem::absolute(options_.appFile, ec).string(), "--host",
                 application_.hosts[i].id, "--control-connect", control, "--bind", binds[i]});
    appendDaemonOptions(argv);
  }
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
    d.bind = binds[i];
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

Status checkLaunch(const app::Application& application, const LaunchOptions& options) {
  if (options.backend != "local" && options.backend != "ssh" && options.backend != "mpirun" &&
      options.backend != "slurm") {
    return makeError("--backend " + options.backend + ": unknown backend");
  }
  if (options.backend == "ssh" && options.hostfile.empty()) {
    return makeError("--backend ssh needs --hosts HOSTFILE (where each host is and how to log in)");
  }
  if (!options.mpirunArgs.empty() && options.backend != "mpirun") {
    return makeError("--mpirun-arg is for --backend mpirun (this launch uses " + options.backend +
                     ")");
  }
  if (options.backend == "slurm") {
    if (auto inside = insideSlurmAllocation(); !inside) return inside;
  }
  if (options.hostfile.empty()) return {};
  auto entries = readHostfile(options.hostfile, application);
  if (!entries) return entries.error();
  if (options.backend == "local" || options.backend == "ssh") {
    for (const auto& e : *entries) {
      if (e.node.empty()) continue;
      return makeError(options.hostfile + ":" + std::to_string(e.line) + ": error: host '" +
                       e.host + "' is placed on machine '" + e.node +
                       "' (node=, or an Open MPI hostfile): only --backend mpirun and slurm "
                       "place hosts on machines");
    }
  }
  return {};
}

Status Launcher::start() {
  const std::string daemonPath = (executableDir() / "vrflow-daemon").string();
  const bool ssh = options_.backend == "ssh";
  const bool slurm = options_.backend == "slurm";
  std::vector<HostEntry> entries;
  if (!options_.hostfile.empty()) {
    auto read = readHostfile(options_.hostfile, application_);
    if (!read) return read.error();
    entries = *read;
  }
  const net::Secret secret = net::newSecret();
  if (options_.backend == "mpirun") {
    if (auto status = startMpirun(daemonPath, secret, entries); !status) return status;
  }
  std::optional<SlurmAllocation> allocation;
  if (slurm) {
    auto found = slurmAllocation();
    if (!found) return found.error();
    allocation = *found;
    if (application_.hosts.size() > allocation->nodes.size()) {
      std::fprintf(stderr,
                   "vrflow: %zu hosts on the %zu node(s) of slurm job %s: several daemons share "
                   "a node\n",
                   application_.hosts.size(), allocation->nodes.size(), allocation->jobId.c_str());
    }
  }
  for (std::size_t i = 0; i < application_.hosts.size() && options_.backend != "mpirun"; ++i) {
    const app::Host& host = application_.hosts[i];
    HostDaemon d;
    d.index = static_cast<int>(i);
    d.host = host.id;
    const HostEntry* entry = nullptr;
    for (const auto& e : entries) {
      if (e.host == host.id) entry = &e;
    }
    Placement placement;
    if (slurm) {
      auto placed = slurmPlacement(*allocation, i, entry);
      if (!placed) return placed.error();
      placement = *placed;
    } else {
      // local: every host on its own loopback address, as a cluster would be.
      placement.bind = "127.0.0." + std::to_string(i + 1);
      if (entry != nullptr) {
        if (!entry->address.empty()) placement.bind = entry->address;
        placement.environment = entry->environment;
      }
    }
    if (ssh) {
      if (entry == nullptr) {
        return makeError(options_.hostfile + ": error: no line for host '" + host.id +
                         "' (--backend ssh needs one per host)");
      }
      if (entry->address.empty()) placement.bind = host.address;
    }
    d.bind = placement.bind;
    std::vector<std::string> environment = placement.environment;
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
    if (slurm) {
      // srun exports this environment (with the hostfile's env=) to the daemon.
      auto srun = srunCommand(placement.node, host.id);
      argv.insert(argv.begin(), srun.begin(), srun.end());
      d.viaSrun = true;
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

}  // namespace vrflow::launcher::detail
