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

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/expand.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/overrides.hpp"
#include "vrflow/app/package_files.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/daemon/plugin.hpp"
#include "vrflow/run/runner.hpp"
#ifdef VRFLOW_HAS_LAUNCHER
#include "vrflow/launcher/launch.hpp"
#endif

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

// Loads the file and expands its composites (search path: the file's folder, --composites,
// $VRFLOW_COMPOSITE_PATH), applies the --set parameters, and validates the flat application when
// a catalog is given; with `files`, also checks the files its modules name on this machine.
// Prints every diagnostic; returns the flat application when there is no error.
std::optional<vrflow::app::Application> loadFlat(
    const std::string& file, const std::vector<std::string>& compositeDirs,
    const std::vector<std::string>& overrides, vrflow::app::Catalog* catalog,
    std::optional<vrflow::app::ModuleFileChecks> files = std::nullopt) {
  std::vector<vrflow::app::Diagnostic> problems;
  auto application = vrflow::app::loadApplicationFile(file, &problems);
  if (!application) {
    std::fprintf(stderr, "%s\n", application.error().message.c_str());
    return std::nullopt;
  }
  // Settings of the file's own composite instances change what the expansion makes.
  std::vector<std::string> moduleSettings = overrides;
  vrflow::app::applyInstanceOverrides(*application, moduleSettings);
  const auto sources = vrflow::app::defaultCompositeSources(*application, compositeDirs);
  auto flat = vrflow::app::expandComposites(*application, sources, &problems);
  if (!flat) {
    std::fprintf(stderr, "%s\n", flat.error().message.c_str());
    return std::nullopt;
  }
  if (auto set = vrflow::app::applyOverrides(*flat, moduleSettings); !set) {
    std::fprintf(stderr, "vrflow: %s\n", set.error().message.c_str());
    return std::nullopt;
  }
  if (catalog != nullptr) {
    auto plugins = vrflow::daemon::loadApplicationPlugins(*flat, *catalog);
    problems.insert(problems.end(), plugins.begin(), plugins.end());
    auto more = vrflow::app::validate(*flat, *catalog);
    problems.insert(problems.end(), more.begin(), more.end());
    if (files) {
      auto named = vrflow::app::checkModuleFiles(*flat, *catalog, *files);
      problems.insert(problems.end(), named.begin(), named.end());
    }
  }
  vrflow::app::sortAndDeduplicate(problems);
  const std::size_t printed = std::min(problems.size(), kMaxPrintedDiagnostics);
  for (std::size_t i = 0; i < printed; ++i) {
    std::fprintf(stderr, "%s\n", vrflow::app::formatDiagnostic(problems[i]).c_str());
  }
  if (problems.size() > printed) {
    std::fprintf(stderr, "... and %zu more problems\n", problems.size() - printed);
  }
  if (vrflow::app::hasErrors(problems)) return std::nullopt;
  return std::move(*flat);
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a closed stderr must not kill the run before its report
  CLI::App cli{"vrflow: run data-flow networks of physics modules"};
  cli.require_subcommand(1);
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
  run->add_flag("--no-progress", noProgress, "Do not show live progress on a terminal");
  run->add_option("--module-memory-limit", options.moduleMemoryBytes,
                  "Cap each module's data memory (e.g. 2G, 512M); hitting it is named as the cause")
      ->transform(CLI::AsSizeValue(false));
  run->add_option("--trace", options.tracePath,
                  "Write a Chrome/Perfetto trace (modules' wait/compute spans, messages as flows)");

#ifdef VRFLOW_HAS_LAUNCHER
  auto* launch = cli.add_subcommand(
      "launch", "Run an application with one daemon per host (TCP between them)");
  vrflow::launcher::LaunchOptions launchOptions;
  launch->add_option("APP.xml", launchOptions.appFile, "Application file")->required();
  SharedOptions launchShared;
  addSharedOptions(*launch, launchShared);
  launch->add_option("--hosts", launchOptions.hostfile,
                     "Hostfile: where each host runs (docs/launcher.md)");
  launch
      ->add_option("--backend", launchOptions.backend,
                   "How daemons are started: local, ssh, mpirun")
      ->check(CLI::IsMember({"local", "ssh", "mpirun"}));
  launch
      ->add_option("--iterations,-n", launchOptions.iterations,
                   "Stop after N iterations of every module")
      ->check(iterationCount());
  launch->add_option("--report", launchOptions.reportPath, "Write a JSON run report to FILE");
  launch
      ->add_option("--timeout", launchOptions.timeoutSeconds,
                   "Fail if the run lasts longer (seconds, > 0; without it, no limit)")
      ->check(positiveSeconds(" (leave --timeout out to run without a time limit)"));
  launch->add_option("--control-address", launchOptions.controlAddress,
                     "mpirun: this machine's address as the daemons reach it (default 127.0.0.1)");
  launch->add_option("--trace", launchOptions.tracePath,
                     "Write a Chrome/Perfetto trace of every host, clocks aligned");
  launch
      ->add_option(
          "--module-memory-limit", launchOptions.moduleMemoryBytes,
          "Cap each module's data memory (e.g. 2G, 512M); hitting it is named as the cause")
      ->transform(CLI::AsSizeValue(false));
  launch
      ->add_option("--peer-timeout", launchOptions.peerTimeoutSeconds,
                   "A host silent this long (no heartbeat) is declared lost (seconds, > 0)")
      ->check(positiveSeconds());
  auto* monitorCommand =
      cli.add_subcommand("monitor", "Show live statistics of the running launches");
  bool monitorOnce = false, monitorJson = false;
  monitorCommand->add_flag("--once", monitorOnce, "Print one snapshot and exit");
  monitorCommand->add_flag("--json", monitorJson, "Print the raw snapshots (JSON lines)");
#endif
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : vrflow::run::kExitInvalid;
  }

#ifdef VRFLOW_HAS_LAUNCHER
  if (monitorCommand->parsed()) return vrflow::launcher::monitor(monitorOnce, monitorJson);
#endif
  SharedOptions shared = before;
  for (const SharedOptions* after : {&validateShared, &expandShared, &runShared}) {
    shared.append(*after);
  }
#ifdef VRFLOW_HAS_LAUNCHER
  shared.append(launchShared);
#endif
  if (expand->parsed()) {
    const auto flat = loadFlat(expandFile, shared.compositeDirs, shared.overrides, nullptr);
    if (!flat) return 1;
    std::fputs(vrflow::app::saveApplication(*flat).c_str(), stdout);
    return 0;
  }
  // Output files are checked before anything is loaded or started: a run must not end, after
  // all its work, unable to write what it was asked for.
  std::vector<std::pair<const char*, std::string>> outputs;
  if (run->parsed()) outputs = {{"report", options.reportPath}, {"trace", options.tracePath}};
#ifdef VRFLOW_HAS_LAUNCHER
  if (launch->parsed()) {
    outputs = {{"report", launchOptions.reportPath}, {"trace", launchOptions.tracePath}};
  }
#endif
  for (const auto& [what, path] : outputs) {
    if (const auto problem = outputFileProblem(path)) {
      std::fprintf(stderr, "vrflow: cannot write the %s to '%s': %s\n", what, path.c_str(),
                   problem->c_str());
      return vrflow::run::kExitInvalid;
    }
  }
  auto catalog = vrflow::run::loadCatalog(shared.packageDirs);
  if (!catalog) {
    std::fprintf(stderr, "vrflow: %s\n", catalog.error().message.c_str());
    return vrflow::run::kExitInvalid;
  }
  if (validate->parsed()) {
    return loadFlat(validateFile, shared.compositeDirs, shared.overrides, &*catalog,
                    vrflow::app::ModuleFileChecks{})
               ? 0
               : 1;
  }
#ifdef VRFLOW_HAS_LAUNCHER
  if (launch->parsed()) {
    auto flat = loadFlat(launchOptions.appFile, shared.compositeDirs, shared.overrides, &*catalog);
    if (!flat) return vrflow::run::kExitInvalid;
    launchOptions.packageDirs = shared.packageDirs;
    launchOptions.compositeDirs = shared.compositeDirs;
    launchOptions.overrides = shared.overrides;
    const auto outcome = vrflow::launcher::launch(*flat, launchOptions);
    if (outcome.exitCode != 0) std::fprintf(stderr, "vrflow: %s\n", outcome.error.c_str());
    return outcome.exitCode;
  }
#endif
  auto application = loadFlat(runFile, shared.compositeDirs, shared.overrides, &*catalog,
                              vrflow::app::ModuleFileChecks{.executables = true});
  if (!application) return vrflow::run::kExitInvalid;
  options.segmentBytes = static_cast<std::size_t>(shmMiB * 1024 * 1024);
  options.progress = !noProgress && isatty(STDERR_FILENO) != 0;
  const auto outcome = vrflow::run::runApplication(*application, *catalog, options);
  if (outcome.exitCode != 0) std::fprintf(stderr, "vrflow: %s\n", outcome.error.c_str());
  return outcome.exitCode;
}
