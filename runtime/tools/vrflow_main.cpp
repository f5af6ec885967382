// The `vrflow` command: validate and run application files.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/diagnostic.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/daemon/plugin.hpp"
#include "vrflow/run/runner.hpp"

namespace {

namespace fs = std::filesystem;

// Packages: --packages folders, then $VRFLOW_PACKAGE_PATH, then the ones installed beside
// this executable (<bin>/../share/vrflow/packages). Filter plugins: $VRFLOW_FILTER_PATH.
vrflow::Result<vrflow::app::Catalog> loadCatalog(const std::vector<std::string>& extra) {
  std::vector<std::string> dirs = extra;
  for (const auto& d : vrflow::app::searchPathFromEnvironment()) dirs.push_back(d);
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back((self.parent_path().parent_path() / "share/vrflow/packages").string());
  vrflow::app::Catalog catalog;
  if (auto status = catalog.loadSearchPath(dirs); !status) return status.error();
  const auto plugins = vrflow::daemon::filterPluginsFromEnvironment();
  if (auto status = vrflow::daemon::loadFilterPlugins(plugins, catalog); !status) {
    return status.error();
  }
  return catalog;
}

// Loads, loads the filter plugins it names, and validates; prints every diagnostic. Returns
// the application when it has no error.
std::optional<vrflow::app::Application> loadValid(const std::string& file,
                                                  vrflow::app::Catalog& catalog) {
  std::vector<vrflow::app::Diagnostic> problems;
  auto application = vrflow::app::loadApplicationFile(file, &problems);
  if (!application) {
    std::fprintf(stderr, "%s\n", application.error().message.c_str());
    return std::nullopt;
  }
  auto plugins = vrflow::daemon::loadApplicationPlugins(*application, catalog);
  problems.insert(problems.end(), plugins.begin(), plugins.end());
  auto more = vrflow::app::validate(*application, catalog);
  problems.insert(problems.end(), more.begin(), more.end());
  vrflow::app::sortAndDeduplicate(problems);
  for (const auto& d : problems) std::fprintf(stderr, "%s\n", vrflow::app::formatDiagnostic(d).c_str());
  if (vrflow::app::hasErrors(problems)) return std::nullopt;
  return std::move(*application);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"vrflow: run data-flow networks of physics modules"};
  cli.require_subcommand(1);
  std::vector<std::string> packageDirs;
  cli.add_option("--packages", packageDirs, "Extra folder of node packages (repeatable)");

  auto* validate = cli.add_subcommand("validate", "Check an application file; exit 0 when valid");
  std::string validateFile;
  validate->add_option("APP.xml", validateFile, "Application file")->required();

  auto* run = cli.add_subcommand("run", "Run an application with every host on this machine");
  validate->fallthrough();
  run->fallthrough();
  std::string runFile;
  vrflow::run::RunOptions options;
  double shmMiB = 1024;
  bool noProgress = false;
  run->add_option("APP.xml", runFile, "Application file")->required();
  run->add_option("--iterations,-n", options.iterations, "Stop after N iterations of every module");
  run->add_option("--report", options.reportPath, "Write a JSON run report to FILE");
  run->add_option("--timeout", options.timeoutSeconds, "Fail if the run lasts longer (seconds)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--deadlock-timeout", options.deadlockSeconds,
                  "Report a deadlock after this long without progress (seconds)")
      ->check(CLI::PositiveNumber);
  run->add_option("--shm-size", shmMiB, "Shared-memory segment size in MiB (sparse)")
      ->check(CLI::Range(1.0, 262144.0));
  run->add_flag("--no-progress", noProgress, "Do not show live progress on a terminal");

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : vrflow::run::kExitInvalid;
  }

  auto catalog = loadCatalog(packageDirs);
  if (!catalog) {
    std::fprintf(stderr, "vrflow: %s\n", catalog.error().message.c_str());
    return vrflow::run::kExitInvalid;
  }
  if (validate->parsed()) {
    return loadValid(validateFile, *catalog) ? 0 : 1;
  }
  auto application = loadValid(runFile, *catalog);
  if (!application) return vrflow::run::kExitInvalid;
  options.segmentBytes = static_cast<std::size_t>(shmMiB * 1024 * 1024);
  options.progress = !noProgress && isatty(STDERR_FILENO) != 0;
  const auto outcome = vrflow::run::runApplication(*application, *catalog, options);
  if (outcome.exitCode != 0) std::fprintf(stderr, "vrflow: %s\n", outcome.error.c_str());
  return outcome.exitCode;
}
