// The `vrflow` command: validate, expand and run application files.
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "record_commands.hpp"
#include "runs_commands.hpp"
#include "types_command.hpp"
#include "vrflow/app/package_files.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/base/version.hpp"
#include "vrflow/launcher/launch.hpp"
#include "vrflow/run/events.hpp"
#include "vrflow/run/log.hpp"
#include "vrflow/run/prepare.hpp"
#include "vrflow/run/run_folders.hpp"
#include "vrflow/run/runner.hpp"

namespace {

// At most this many diagnostics are printed (a screenful), then how many more there are.
constexpr std::size_t kMaxPrintedDiagnostics = 20;

// --packages, --composites and --set, accepted before the subcommand and after it.
struct SharedOptions {
  std::vector<std::string> packageDirs, compositeDirs, overrides;

  void append(const SharedOptions& other) {
    packageDirs.insert(packageDirs.end(), other.packageDirs.begin(), other.packageDirs.end());
    compositeDirs.insert(compositeDirs.end(), other.compositeDirs.begin(),
                         other.compositeDirs.end());
    overrides.insert(overrides.end(), other.overrides.begin(), other.overrides.end());
  }

  // What run::prepare() needs to prepare `file` with these options.
  vrflow::run::PrepareSettings settings(const std::string& file, bool validate) const {
    return {.file = file,
            .packageDirs = packageDirs,
            .compositeDirs = compositeDirs,
            .overrides = overrides,
            .validate = validate,
            .files = std::nullopt,
            .program = "vrflow"};
  }
};

void addSharedOptions(CLI::App& command, SharedOptions& into) {
  // One value per occurrence: a repeatable option must not swallow the APP.xml after it.
  command.add_option("--packages", into.packageDirs, "Extra folder of node packages (repeatable)")
      ->allow_extra_args(false);
  command
      .add_option("--composites", into.compositeDirs,
                  "Extra folder of composite files NAME.vrc.xml (repeatable)")
      ->allow_extra_args(false);
  command
      .add_option("--set", into.overrides,
                  "ID.PARAM=VALUE: set a parameter of a module or filter over the file's "
                  "(repeatable; validated as if written in the file)")
      ->allow_extra_args(false);
}

// Seconds, a finite number > 0; `hint` follows the message for 0 or less.
CLI::Validator positiveSeconds(std::string hint = {}) {
  return CLI::Validator(
      [hint](std::string& text) -> std::string {
        char* end = nullptr;
        errno = 0;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE ||
            !std::isfinite(value)) {
          return "'" + text + "' is not a number of seconds";
        }
        if (value <= 0) return "must be more than 0 seconds, got '" + text + "'" + hint;
        return {};
      },
      "SECONDS>0");
}

// An iteration count: decimal digits, at most 2^62.
CLI::Validator iterationCount() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool digits = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
          return c >= '0' && c <= '9';
        });
        if (!digits) return "'" + text + "' is not a number (expected a count of iterations)";
        if (text.size() > 19 || std::stoull(text) > (uint64_t{1} << 62)) {
          return "'" + text + "' is too large (at most " + std::to_string(uint64_t{1} << 62) + ")";
        }
        return {};
      },
      "N");
}

// Why a file cannot be written at `path` (its folder missing or not writable, a folder in its
// place), or nullopt. Nothing is created.
std::optional<std::string> outputFileProblem(const std::string& path) {
  if (path.empty()) return std::nullopt;
  struct stat info {};
  if (stat(path.c_str(), &info) == 0) {
    if (S_ISDIR(info.st_mode)) return "it is a folder";
    if (access(path.c_str(), W_OK) != 0) return "the file is not writable";
    return std::nullopt;
  }
  if (errno != ENOENT) return std::string(std::strerror(errno));
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  const std::string folder = parent.empty() ? "." : parent.string();
  if (stat(folder.c_str(), &info) != 0) {
    if (errno == ENOENT) return "folder '" + folder + "' does not exist";
    return "folder '" + folder + "': " + std::strerror(errno);
  }
  if (!S_ISDIR(info.st_mode)) return "'" + folder + "' is not a folder";
  if (access(folder.c_str(), W_OK | X_OK) != 0) return "folder '" + folder + "' is not writable";
  return std::nullopt;
}

// Prepares the file (run::prepare) and prints its problems; the flat application when there is
// no error.
std::optional<vrflow::app::Application> loadFlat(vrflow::run::PrepareSettings settings,
                                                 vrflow::run::Prepared* into = nullptr) {
  vrflow::run::Prepared prepared = vrflow::run::prepare(settings);
  vrflow::run::printProblems(prepared, kMaxPrintedDiagnostics);
  std::optional<vrflow::app::Application> flat = std::move(prepared.application);
  if (into != nullptr) *into = std::move(prepared);
  return flat;
}

// --log-dir and --log-level of `run` and `launch` (docs/logs.md).
void addLogOptions(CLI::App& command, std::string& logDir, std::string& logLevel) {
  command.add_option("--log-dir", logDir,
                     "Write the modules' logs (MODULE.log) and the runtime's (vrflow.log) to DIR "
                     "(made, mode 0700, if missing; default: a folder per run, printed at start)");
  command
      .add_option("--log-level", logLevel,
                  "The runtime's own lines shown and logged: trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
}

// Gives the run of `application` its id and log folder (the default one, made now, when none
// was given), sends the runtime's lines there too, and says where they are. False when the
// folder cannot be used (said on stderr).
bool startLogs(const std::string& application, const std::string& level, std::string& runId,
               std::string& logDir) {
  runId = vrflow::run::newRunId(application);
  if (logDir.empty()) {
    logDir = vrflow::run::defaultLogDirectory(runId);
    if (auto made = vrflow::run::prepareLogDirectory(logDir); !made) {
      std::fprintf(stderr, "vrflow: %s\n", made.error().message.c_str());
      return false;
    }
  }
  auto status = vrflow::run::setupLogging(*vrflow::run::parseLogLevel(level), logDir);
  if (!status) {
    std::fprintf(stderr, "vrflow: %s\n", status.error().message.c_str());
    return false;
  }
  vrflow::run::logInfo("vrflow: run " + runId + ", logs in " + logDir);
  return true;
}

// What stderr shows of a run: a live line on a terminal, else one summary line at the end.
vrflow::run::ProgressMode progressMode(bool noProgress) {
  if (noProgress) return vrflow::run::ProgressMode::Off;
  return isatty(STDERR_FILENO) != 0 ? vrflow::run::ProgressMode::Live
                                    : vrflow::run::ProgressMode::Summary;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a closed stderr must not kill the run before its report
  CLI::App cli{"vrflow: run data-flow networks of physics modules"};
  cli.require_subcommand(1);
  // `vrflow --version` is answered before main() (vrflow/base/version.hpp); the flag is here for
  // --help and for `--version` among other arguments.
  cli.set_version_flag("--version", vrflow::versionLine("vrflow"), "Print the version and exit");
  // The common options are accepted before the subcommand and after it (each subcommand's
  // --help lists them); both are used, those before first.
  SharedOptions before;
  addSharedOptions(cli, before);

  auto* validate = cli.add_subcommand("validate", "Check an application file; exit 0 when valid");
  std::string validateFile;
  validate->add_option("APP.xml", validateFile, "Application file")->required();
  SharedOptions validateShared;
  addSharedOptions(*validate, validateShared);

  auto* expand = cli.add_subcommand("expand", "Print the application with its composites expanded");
  std::string expandFile;
  expand->add_option("APP.xml", expandFile, "Application file")->required();
  SharedOptions expandShared;
  addSharedOptions(*expand, expandShared);

  auto* run = cli.add_subcommand("run", "Run an application with every host on this machine");
  std::string runFile;
  vrflow::run::RunOptions options;
  double shmMiB = 1024;
  bool noProgress = false;
  run->add_option("APP.xml", runFile, "Application file")->required();
  SharedOptions runShared;
  addSharedOptions(*run, runShared);
  run->add_option("--iterations,-n", options.iterations, "Stop after N iterations of every module")
      ->check(iterationCount());
  run->add_option("--report", options.reportPath, "Write a JSON run report to FILE");
  run->add_option("--timeout", options.timeoutSeconds,
                  "Fail if the run lasts longer (seconds, > 0; without it, no limit)")
      ->check(positiveSeconds(" (leave --timeout out to run without a time limit)"));
  run->add_option("--deadlock-timeout", options.deadlockSeconds,
                  "Report a deadlock after this long without progress (seconds, > 0)")
      ->check(positiveSeconds());
  run->add_option("--shm-size", shmMiB, "Shared-memory segment size in MiB (sparse)")
      ->check(CLI::Range(1.0, 262144.0));
  run->add_flag("--no-progress", noProgress,
                "Show no progress (on a terminal a live line, else a summary line at the end)");
  run->add_option("--module-memory-limit", options.moduleMemoryBytes,
                  "Cap each module's data memory (e.g. 2G, 512M); hitting it is named as the cause")
      ->transform(CLI::AsSizeValue(false));
  run->add_option("--trace", options.tracePath,
                  "Write a Chrome/Perfetto trace (modules' wait/compute spans, messages as flows)");
  std::string logLevel = "info";
  addLogOptions(*run, options.logDir, logLevel);
  std::string eventsTarget;
  run->add_option("--events", eventsTarget,
                  "Write the run's events as JSON lines to FILE, or to stdout with '-' "
                  "(docs/events.md)");

  auto* launch = cli.add_subcommand(
      "launch", "Run an application with one daemon per host (TCP between them)");
  vrflow::launcher::LaunchOptions launchOptions;
  launch->add_option("APP.xml", launchOptions.appFile, "Application file")->required();
  SharedOptions launchShared;
  addSharedOptions(*launch, launchShared);
  launch->add_option("--hosts", launchOptions.hostfile,
                     "Hostfile, vrflow's or Open MPI's: where each host runs (docs/launcher.md)");
  launch
      ->add_option("--backend", launchOptions.backend,
                   "How daemons are started: local, ssh, mpirun, slurm (inside an allocation)")
      ->check(CLI::IsMember({"local", "ssh", "mpirun", "slurm"}));
  launch->add_option("--mpirun-arg", launchOptions.mpirunArgs,
                     "mpirun: one more word on mpirun's command line, before the ranks "
                     "(repeatable; write --mpirun-arg=--oversubscribe for a word starting with -)");
  launch
      ->add_option("--iterations,-n", launchOptions.iterations,
                   "Stop after N iterations of every module")
      ->check(iterationCount());
  launch->add_option("--report", launchOptions.reportPath, "Write a JSON run report to FILE");
  launch
      ->add_option("--timeout", launchOptions.timeoutSeconds,
                   "Fail if the run lasts longer (seconds, > 0; without it, no limit)")
      ->check(positiveSeconds(" (leave --timeout out to run without a time limit)"));
  launch->add_flag("--no-progress", noProgress,
                   "Show no progress (on a terminal a live line, else a summary line at the end)");
  launch->add_option("--control-address", launchOptions.controlAddress,
                     "mpirun: this machine's address as the daemons reach it (default 127.0.0.1)");
  launch->add_option("--trace", launchOptions.tracePath,
                     "Write a Chrome/Perfetto trace of every host, clocks aligned");
  launch->add_option("--events", eventsTarget,
                     "Write the events of every host as JSON lines to FILE, or to stdout with '-' "
                     "(docs/events.md)");
  launch
      ->add_option(
          "--module-memory-limit", launchOptions.moduleMemoryBytes,
          "Cap each module's data memory (e.g. 2G, 512M); hitting it is named as the cause")
      ->transform(CLI::AsSizeValue(false));
  addLogOptions(*launch, launchOptions.logDir, logLevel);
  launch
      ->add_option("--peer-timeout", launchOptions.peerTimeoutSeconds,
                   "A host silent this long (no heartbeat) is declared lost (seconds, > 0)")
      ->check(positiveSeconds());
  auto* monitorCommand =
      cli.add_subcommand("monitor", "Show live statistics of a running run or launch");
  bool monitorOnce = false, monitorJson = false;
  std::string monitorRun;
  monitorCommand->add_option("RUN", monitorRun,
                             "Run id, or any unique start of it (default: the only running run)");
  monitorCommand->add_flag("--once", monitorOnce, "Print one snapshot and exit");
  monitorCommand->add_flag("--json", monitorJson, "Print the raw snapshots (JSON lines)");
  bool monitorFollowEvents = false;
  monitorCommand->add_flag("--follow-events", monitorFollowEvents,
                           "Print the run's events as JSON lines as they come, until it ends "
                           "(docs/events.md)");
  std::string monitorSource;
  monitorCommand->add_option("--events", monitorSource,
                             "Show an event stream (FILE, or '-' for stdin) instead of the "
                             "running runs (docs/events.md)");
  vrflow::apps::TypesOptions typesOptions;
  auto* typesCommand = vrflow::apps::addTypesCommand(cli, typesOptions);
  vrflow::cli::RunsCommands runsCommands;
  vrflow::cli::addRunsCommands(cli, runsCommands);
  vrflow::cli::RecordCommands recordCommands;
  vrflow::cli::addRecordCommands(cli, recordCommands);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : vrflow::run::kExitInvalid;
  }

  if (const auto code = vrflow::cli::runRunsCommand(runsCommands)) return *code;
  if (const auto code = vrflow::cli::runRecordCommand(recordCommands)) return *code;
  if (monitorCommand->parsed()) {
    if (monitorFollowEvents) return vrflow::launcher::followEvents(monitorRun);
    return monitorSource.empty()
               ? vrflow::launcher::monitor(monitorRun, monitorOnce, monitorJson)
               : vrflow::launcher::monitorEvents(monitorSource, monitorOnce, monitorJson);
  }
  if (typesCommand->parsed()) {
    typesOptions.packageDirs.insert(typesOptions.packageDirs.begin(), before.packageDirs.begin(),
                                    before.packageDirs.end());
    return vrflow::apps::runTypes(typesOptions);
  }
  SharedOptions shared = before;
  for (const SharedOptions* after : {&validateShared, &expandShared, &runShared}) {
    shared.append(*after);
  }
  shared.append(launchShared);
  if (expand->parsed()) {
    const auto flat = loadFlat(shared.settings(expandFile, /*validate=*/false));
    if (!flat) return 1;
    std::fputs(vrflow::app::saveApplication(*flat).c_str(), stdout);
    return 0;
  }
  // Output files are checked before anything is loaded or started (the event stream's first,
  // so that it can say why the others are refused): a run must not end, after
  // all its work, unable to write what it was asked for.
  std::vector<std::pair<const char*, std::string>> outputs;
  if (run->parsed()) {
    outputs = {{"report", options.reportPath}, {"trace", options.tracePath}};
  }
  if (launch->parsed()) {
    outputs = {{"report", launchOptions.reportPath}, {"trace", launchOptions.tracePath}};
  }
  std::unique_ptr<vrflow::run::EventStream> events;
  if (!eventsTarget.empty()) {
    if (eventsTarget != "-") {
      if (const auto problem = outputFileProblem(eventsTarget)) {
        std::fprintf(stderr, "vrflow: cannot write the events to '%s': %s\n", eventsTarget.c_str(),
                     problem->c_str());
        return vrflow::run::kExitInvalid;
      }
    }
    auto opened = vrflow::run::EventStream::open(eventsTarget);
    if (!opened) {
      std::fprintf(stderr, "vrflow: %s\n", opened.error().message.c_str());
      return vrflow::run::kExitInvalid;
    }
    events = std::move(*opened);
    // The stream has standard output to itself: what modules print goes to stderr instead.
    if (eventsTarget == "-") dup2(STDERR_FILENO, STDOUT_FILENO);
    options.events = events.get();
    launchOptions.events = events.get();
  }
  for (const auto& [what, path] : outputs) {
    if (const auto problem = outputFileProblem(path)) {
      const std::string text =
          "cannot write the " + std::string(what) + " to '" + path + "': " + *problem;
      std::fprintf(stderr, "vrflow: %s\n", text.c_str());
      if (events) events->end({vrflow::run::kExitInvalid, "invalid", text});
      return vrflow::run::kExitInvalid;
    }
  }
  // A log folder given is made and checked with the other outputs, before anything starts.
  std::string* logDir = run->parsed()      ? &options.logDir
                        : launch->parsed() ? &launchOptions.logDir
                                           : nullptr;
  if (logDir != nullptr && !logDir->empty()) {
    if (auto made = vrflow::run::prepareLogDirectory(*logDir); !made) {
      std::fprintf(stderr, "vrflow: %s\n", made.error().message.c_str());
      if (events) events->end({vrflow::run::kExitInvalid, "invalid", made.error().message});
      return vrflow::run::kExitInvalid;
    }
  }
  // An application that cannot run still ends its event stream, with its first problem.
  const auto refused = [&](const vrflow::run::Prepared& prepared) {
    if (events) {
      std::string first = prepared.error;
      for (const auto& d : prepared.diagnostics) {
        if (first.empty() && d.severity == vrflow::app::Diagnostic::Error) {
          first = vrflow::app::formatDiagnostic(d);
        }
      }
      events->end({vrflow::run::kExitInvalid, "invalid", first});
    }
    return vrflow::run::kExitInvalid;
  };
  // A catalog that cannot be loaded is a mistake in what was given (exit 2), whatever the command.
  const auto invalid = [](const vrflow::run::Prepared& prepared, int code) {
    return prepared.catalogFailed ? vrflow::run::kExitInvalid : code;
  };
  vrflow::run::Prepared prepared;
  if (validate->parsed()) {
    auto settings = shared.settings(validateFile, /*validate=*/true);
    settings.files = vrflow::app::ModuleFileChecks{};
    return loadFlat(settings, &prepared) ? 0 : invalid(prepared, 1);
  }
  if (launch->parsed()) {
    auto flat = loadFlat(shared.settings(launchOptions.appFile, /*validate=*/true), &prepared);
    if (!flat) return refused(prepared);
    launchOptions.packageDirs = shared.packageDirs;
    launchOptions.compositeDirs = shared.compositeDirs;
    launchOptions.overrides = shared.overrides;
    launchOptions.logLevel = logLevel;
    if (!startLogs(flat->name, logLevel, launchOptions.runId, launchOptions.logDir)) {
      return vrflow::run::kExitInvalid;
    }
    launchOptions.progress = progressMode(noProgress);
    const auto outcome = vrflow::launcher::launch(*flat, launchOptions);
    if (outcome.exitCode != 0) vrflow::run::logError("vrflow: " + outcome.error);
    vrflow::run::shutdownLogging();
    return outcome.exitCode;
  }
  auto settings = shared.settings(runFile, /*validate=*/true);
  settings.files = vrflow::app::ModuleFileChecks{.executables = true};
  auto application = loadFlat(settings, &prepared);
  if (!application) return refused(prepared);
  const vrflow::app::Catalog& catalog = *prepared.catalog;
  options.segmentBytes = static_cast<std::size_t>(shmMiB * 1024 * 1024);
  if (!startLogs(application->name, logLevel, options.runId, options.logDir)) {
    return vrflow::run::kExitInvalid;
  }
  options.progress = progressMode(noProgress);
  const auto outcome = vrflow::run::runApplication(*application, catalog, options);
  if (outcome.exitCode != 0) vrflow::run::logError("vrflow: " + outcome.error);
  if (!outcome.detail.empty()) vrflow::run::logError(outcome.detail);
  vrflow::run::shutdownLogging();
  return outcome.exitCode;
}
