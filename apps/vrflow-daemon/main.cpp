// vrflow-daemon: the daemon of one host of an application, with that host's modules. The
// launcher starts one per host (`--control`: it talks to the launcher over stdin/stdout and to
// the other hosts' daemons over TCP); `vrflow run` embeds the same daemon for all hosts at once.
// Alone (without --control) it refuses connections that cross hosts.
#include <fcntl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>

#include "control_link.hpp"
#include "vrflow/base/version.hpp"
#include "vrflow/net/control.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/log.hpp"
#include "vrflow/run/prepare.hpp"
#include "vrflow/run/runner.hpp"

int main(int argc, char** argv) {
  // The launcher gone, writes on the control channel fail (EPIPE) instead of killing the
  // daemon before it stops its modules (spawnProcess() gives children SIGPIPE's default).
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App cli{"vrflow-daemon: serve one host of an application"};
  std::string file, host;
  std::vector<std::string> packageDirs;
  vrflow::run::RunOptions options;
  cli.add_option("APP.xml", file, "Application file")->required();
  cli.add_option("--host", host,
                 "Host id (as in the application file) this daemon serves (required, except "
                 "under mpirun with --control-connect: the host of the rank's index)");
  cli.add_option("--packages", packageDirs, "Extra folder of node packages (repeatable)");
  std::vector<std::string> compositeDirs;
  cli.add_option("--composites", compositeDirs,
                 "Extra folder of composite files NAME.vrc.xml (repeatable)");
  std::vector<std::string> overrides;
  cli.add_option("--set", overrides,
                 "ID.PARAM=VALUE: set a parameter of a module or filter over the file's "
                 "(repeatable)");
  cli.add_option("--iterations,-n", options.iterations, "Stop after N iterations of every module");
  cli.add_option("--report", options.reportPath, "Write a JSON run report to FILE");
  cli.add_option("--timeout", options.timeoutSeconds, "Fail if the run lasts longer (seconds)");
  bool control = false;
  std::string bindAddress;
  double peerTimeout = 3.0;
  cli.add_flag("--control", control,
               "Run under `vrflow launch`: the run secret and commands come on stdin, events go "
               "to stdout, connections crossing hosts go over TCP");
  std::string controlConnect;
  cli.add_option("--control-connect", controlConnect,
                 "Run under `vrflow launch --backend mpirun`: reach the launcher at ADDRESS:PORT; "
                 "the run secret is read from $VRFLOW_RUN_SECRET, which is cleared at once");
  cli.add_flag("--trace", options.trace, "Record modules' spans and send them to the launcher");
  cli.add_option("--module-memory-limit", options.moduleMemoryBytes,
                 "Cap each module's data memory (e.g. 2G, 512M)")
      ->transform(CLI::AsSizeValue(false));
  cli.add_option("--bind", bindAddress, "Address to listen on (default: the host's address)");
  cli.add_option("--peer-timeout", peerTimeout,
                 "A link to another host silent this long is declared lost (seconds)")
      ->check(CLI::PositiveNumber);
  cli.add_option("--log-dir", options.logDir,
                 "Keep this host's module logs (MODULE.log) and the daemon's (vrflow.log) in DIR "
                 "(made, mode 0700, if missing); under the launcher, they also reach its machine");
  std::string logLevel = "info";
  cli.add_option("--log-level", logLevel,
                 "The daemon's own lines shown and logged: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  std::string launcherVersion;
  cli.add_option("--launcher-version", launcherVersion,
                 "The launcher's version (vrflow launch passes it): refuse to serve under a "
                 "launcher of another version");
  cli.set_version_flag("--version", std::string(vrflow::versionText()),
                       "Print the version and exit");
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? 0 : vrflow::run::kExitInvalid;
  }
  if (!options.logDir.empty()) {
    if (auto made = vrflow::run::prepareLogDirectory(options.logDir); !made) {
      std::fprintf(stderr, "vrflow-daemon: %s\n", made.error().message.c_str());
      return vrflow::run::kExitInvalid;
    }
  }
  if (auto status =
          vrflow::run::setupLogging(*vrflow::run::parseLogLevel(logLevel), options.logDir);
      !status) {
    std::fprintf(stderr, "vrflow-daemon: %s\n", status.error().message.c_str());
    return vrflow::run::kExitInvalid;
  }

  vrflow::run::Prepared prepared = vrflow::run::prepare({.file = file,
                                                         .packageDirs = packageDirs,
                                                         .compositeDirs = compositeDirs,
                                                         .overrides = overrides,
                                                         .validate = true,
                                                         .files = std::nullopt,
                                                         .program = "vrflow-daemon"});
  vrflow::run::printProblems(prepared);
  if (!prepared.ok()) return vrflow::run::kExitInvalid;
  const vrflow::app::Catalog& catalog = *prepared.catalog;
  std::optional<vrflow::app::Application> application = std::move(prepared.application);
  std::optional<vrflow::net::Secret> secret;
  if (!controlConnect.empty()) {
    const char* text = std::getenv("VRFLOW_RUN_SECRET");
    if (text == nullptr) {
      std::fprintf(stderr, "vrflow-daemon: --control-connect needs $VRFLOW_RUN_SECRET\n");
      return vrflow::run::kExitInvalid;
    }
    auto parsed = vrflow::net::secretFromHex(text);
    std::memset(const_cast<char*>(text), 0, std::strlen(text));
    unsetenv("VRFLOW_RUN_SECRET");  // modules must not inherit it
    if (!parsed) {
      std::fprintf(stderr, "vrflow-daemon: $VRFLOW_RUN_SECRET: %s\n",
                   parsed.error().message.c_str());
      return vrflow::run::kExitInvalid;
    }
    secret = *parsed;
    if (host.empty()) {
      const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
      const long index = rank != nullptr ? std::atol(rank) : -1;
      if (index < 0 || static_cast<std::size_t>(index) >= application->hosts.size()) {
        std::fprintf(stderr,
                     "vrflow-daemon: %s: no --host, and MPI rank %s names no host of the file\n",
                     file.c_str(), rank != nullptr ? rank : "(none)");
        return vrflow::run::kExitInvalid;
      }
      host = application->hosts[static_cast<std::size_t>(index)].id;
    }
  }
  if (host.empty()) {
    std::fprintf(stderr, "vrflow-daemon: --host is required\n");
    return vrflow::run::kExitInvalid;
  }
  if (vrflow::app::findHost(*application, host) == nullptr && host != "localhost") {
    std::fprintf(stderr, "vrflow-daemon: %s: no host '%s' in the application\n", file.c_str(),
                 host.c_str());
    return vrflow::run::kExitInvalid;
  }
  // Hosts of one launch must run the same vrflow: the control lines, the frames between daemons
  // and the report shares are only known to agree within one version.
  if (!launcherVersion.empty() && launcherVersion != vrflow::versionText()) {
    const std::string text = "vrflow-daemon here is vrflow " + std::string(vrflow::versionText()) +
                             ", the launcher is vrflow " + launcherVersion +
                             ": install the same vrflow on every host";
    std::fprintf(stderr, "vrflow-daemon (host %s): %s\n", host.c_str(), text.c_str());
    // On the control channel too, so that the launcher's one message names this host.
    if (control)
      std::printf("%s\n", vrflow::net::toLine(vrflow::net::ControlEvent::error(text)).c_str());
    return vrflow::run::kExitInvalid;
  }

  // Under the launcher, the control channel is this process's stdin/stdout: keep them for it,
  // and give modules (which inherit fds 0 and 1) /dev/null and stderr instead.
  std::unique_ptr<vrflow::tools::ControlLink> link;
  std::unique_ptr<vrflow::run::EventStream> events;  // declared after `link`: destroyed before
  if (control || !controlConnect.empty()) {
    int in = -1, out = -1;
    if (control) {
      in = dup(STDIN_FILENO);
      out = dup(STDOUT_FILENO);
    } else {
      int index = 0;
      for (std::size_t i = 0; i < application->hosts.size(); ++i) {
        if (application->hosts[i].id == host) index = static_cast<int>(i);
      }
      auto fd = vrflow::tools::ControlLink::connectBack(controlConnect, *secret, index);
      if (!fd) {
        std::fprintf(stderr, "vrflow-daemon (host %s): %s\n", host.c_str(),
                     fd.error().message.c_str());
        return vrflow::run::kExitRunFailed;
      }
      in = *fd;
      out = dup(*fd);
    }
    fcntl(in, F_SETFD, FD_CLOEXEC);
    fcntl(out, F_SETFD, FD_CLOEXEC);
    const int null = open("/dev/null", O_RDONLY | O_CLOEXEC);
    dup2(null, STDIN_FILENO);
    dup2(STDERR_FILENO, STDOUT_FILENO);
    close(null);
    auto made = vrflow::tools::ControlLink::create(*application, host, bindAddress, peerTimeout, in,
                                                   out, secret);
    if (!made) {
      std::fprintf(stderr, "vrflow-daemon: %s: %s\n", file.c_str(), made.error().message.c_str());
      return vrflow::run::kExitInvalid;
    }
    link = std::move(*made);
    options.hostLink = link.get();
    // This host's events go to the launcher, which writes the launch's stream; statistics
    // travel on their own control lines (with the links' counters).
    events = std::make_unique<vrflow::run::EventStream>(
        [l = link.get()](const std::string& line) { l->event(line); }, /*withStats=*/false);
    options.events = events.get();
  }

  // Multi-rate: the iterations of each module come from the whole network, before the split.
  if (options.iterations > 0)
    options.moduleIterations = vrflow::run::moduleIterations(*application, options.iterations);

  // Keep this host's share of the network.
  vrflow::app::Application local = *application;
  local.modules.clear();
  local.filters.clear();
  local.connections.clear();
  std::set<std::string> here;
  for (const auto& m : application->modules) {
    if (vrflow::app::effectiveHost(*application, m.host) == host) {
      local.modules.push_back(m);
      here.insert(m.id);
    }
  }
  for (const auto& f : application->filters) {
    if (vrflow::app::effectiveHost(*application, f.host) == host) {
      local.filters.push_back(f);
      here.insert(f.id);
    }
  }
  for (const auto& c : application->connections) {
    const bool from = here.count(c.from.node) != 0;
    const bool to = here.count(c.to.node) != 0;
    if (from != to && link) continue;  // served by the transport (ControlLink::create)
    if (from != to) {
      std::fprintf(stderr,
                   "%s:%d:%d: error: connection %s -> %s crosses hosts; a daemon started alone "
                   "serves one host only: map both ends to host '%s', or start the application "
                   "with `vrflow launch` (or `vrflow run`)\n",
                   c.loc.file.c_str(), c.loc.line, c.loc.column,
                   vrflow::app::toString(c.from).c_str(), vrflow::app::toString(c.to).c_str(),
                   host.c_str());
      return vrflow::run::kExitInvalid;
    }
    if (from) local.connections.push_back(c);
  }
  options.wholeApplication = &*application;
  const auto outcome = vrflow::run::runApplication(local, catalog, options);
  if (link) {
    // The launcher reports the error; the failed module's last lines reach its terminal here.
    if (!outcome.detail.empty()) vrflow::run::logError(outcome.detail);
    return outcome.exitCode;
  }
  if (outcome.exitCode != 0) vrflow::run::logError("vrflow-daemon: " + outcome.error);
  if (!outcome.detail.empty()) vrflow::run::logError(outcome.detail);
  return outcome.exitCode;
}
