#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

// `vrflow record`, `vrflow replay` and `vrflow inspect`: a run with a recorder attached to some
// outputs, a run with modules replaced by the replay of their recorded outputs, and what a
// recording holds (docs/recording.md).
namespace vrflow::cli {

/// The three subcommands and what their command lines hold.
struct RecordCommands {
  CLI::App* record = nullptr;
  CLI::App* replay = nullptr;
  CLI::App* inspect = nullptr;
  std::string appFile;                   ///< record and replay: APP.xml
  std::string recording;                 ///< record -o FILE; replay FILE; inspect FILE
  std::vector<std::string> connections;  ///< record --connections MODULE.PORT,...
  std::vector<std::string> replaced;     ///< replay --replace MODULE (repeatable)
  std::string pace = "recorded";         ///< replay --pace
  int level = 1;                         ///< record --level (zstd)
  bool json = false;                     ///< inspect --json
  std::vector<std::string> packageDirs;  ///< --packages
  std::vector<std::string> overrides;    ///< --set
  std::uint64_t iterations = 0;          ///< --iterations, -n
  std::string reportPath;                ///< --report
  double timeoutSeconds = 0;             ///< --timeout
  bool noProgress = false;               ///< --no-progress
};

/// Adds `record`, `replay` and `inspect` to `cli`, their options held by `into`.
void addRecordCommands(CLI::App& cli, RecordCommands& into);

/// Runs the one of them that was parsed and returns its exit status; nullopt if none was.
std::optional<int> runRecordCommand(RecordCommands& commands);

}  // namespace vrflow::cli
