// The `vrflow` command: validate, expand and run application files.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
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
  for (const auto& d : problems)
    std::fprintf(stderr, "%s\n", vrflow::app::formatDiagnostic(d).c_str());
  if (vrflow::app::hasErrors(problems)) return std::nullopt;
  return std::move(*flat);
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a closed stderr must not kill the run before its report
  CLI::App cli{"vrflow: run data-flow networks of physics modules"};
  cli.require_subcommand(1);
  std::vector<std::string> packageDirs;
  cli.add_option("--packages", packageDirs, "Extra folder of node packages (repeatable)");
  std::vector<std::string> compositeDirs;
  cli.add_option("--composites", compositeDirs,
                 "Extra folder of composite files NAME.vrc.xml (repeatable)");
  std::vector<std::string> overrides;
  cli.add_option("--set", overrides,
                 "ID.PARAM=VALUE: set a parameter of a module or filter over the file's "
                 "(repeatable; validated as if written in the file)");

  auto* validate = cli.add_subcommand("validate", "Check an application file; exit 0 when valid");
  std::string validateFile;
  validate->add_option("APP.xml", validateFile, "Application file")->required();

  auto* expand = cli.add_subcommand("expand", "Print the application with its composites expanded");
  std::string expandFile;
  expand->add_option("APP.xml", expandFile, "Application file")->required();

  auto* run = cli.add_subcommand("run", "Run an application with every host on this machine");
  validate->fallthrough();
  expand->fallthrough();
  run->fallthrough();
  std::string runFile;
  vrflow::run::RunOptions options;
  double shmMiB = 1024;
  bool noProgress = false;
  run->add_option("APP.xml", runFile, "Application file")->required();
  run->add_option("--iterations,-n", options.iterations, "Stop after N iterations of every module")
      ->check(CLI::Range(uint64_t{0}, uint64_t{1} << 62));
  run->add_option("--report", options.reportPath, "Write a JSON run report to FILE");
  run->add_option("--timeout", options.timeoutSeconds, "Fail if the run lasts longer (seconds)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--deadlock-timeout", options.deadlockSeconds,
                  "Report a deadlock after this long without progress (seconds)")
      ->check(CLI::PositiveNumber);
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
  launch->fallthrough();
  vrflow::launcher::LaunchOptions launchOptions;
  launch->add_option("APP.xml", launchOptions.appFile, "Application file")->required();
  launch->add_option("--hosts", launchOptions.hostfile,
                     "Hostfile: where each host runs (docs/launcher.md)");
  launch
      ->add_option("--backend", launchOptions.backend,
                   "How daemons are started: local, ssh, mpirun")
      ->check(CLI::IsMember({"local", "ssh", "mpirun"}));
  launch->add_option("--iterations,-n", launchOptions.iterations,
                     "Stop after N iterations of every module");
  launch->add_option("--report", launchOptions.reportPath, "Write a JSON run report to FILE");
  launch
      ->add_option("--timeout", launchOptions.timeoutSeconds,
                   "Fail if the run lasts longer (seconds)")
      ->check(CLI::NonNegativeNumber);
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
                   "A host silent this long (no heartbeat) is declared lost (seconds)")
      ->check(CLI::PositiveNumber);
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
  if (expand->parsed()) {
    const auto flat = loadFlat(expandFile, compositeDirs, overrides, nullptr);
    if (!flat) return 1;
    std::fputs(vrflow::app::saveApplication(*flat).c_str(), stdout);
    return 0;
  }
  auto catalog = vrflow::run::loadCatalog(packageDirs);
  if (!catalog) {
    std::fprintf(stderr, "vrflow: %s\n", catalog.error().message.c_str());
    return vrflow::run::kExitInvalid;
  }
  if (validate->parsed()) {
    return loadFlat(validateFile, compositeDirs, overrides, &*catalog,
                    vrflow::app::ModuleFileChecks{})
               ? 0
               : 1;
  }
#ifdef VRFLOW_HAS_LAUNCHER
  if (launch->parsed()) {
    auto flat = loadFlat(launchOptions.appFile, compositeDirs, overrides, &*catalog);
    if (!flat) return vrflow::run::kExitInvalid;
    launchOptions.packageDirs = packageDirs;
    launchOptions.compositeDirs = compositeDirs;
    launchOptions.overrides = overrides;
    const auto outcome = vrflow::launcher::launch(*flat, launchOptions);
    if (outcome.exitCode != 0) std::fprintf(stderr, "vrflow: %s\n", outcome.error.c_str());
    return outcome.exitCode;
  }
#endif
  auto application = loadFlat(runFile, compositeDirs, overrides, &*catalog,
                              vrflow::app::ModuleFileChecks{.executables = true});
  if (!application) return vrflow::run::kExitInvalid;
  options.segmentBytes = static_cast<std::size_t>(shmMiB * 1024 * 1024);
  options.progress = !noProgress && isatty(STDERR_FILENO) != 0;
  const auto outcome = vrflow::run::runApplication(*application, *catalog, options);
  if (outcome.exitCode != 0) std::fprintf(stderr, "vrflow: %s\n", outcome.error.c_str());
  return outcome.exitCode;
}
