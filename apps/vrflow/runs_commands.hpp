#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

// `vrflow list`, `vrflow stop` and `vrflow logs`: the runs of this user from the registry
// (vrflow/run/registry.hpp, docs/operations.md).
namespace vrflow::cli {

/// The three subcommands and what their command lines hold.
struct RunsCommands {
  CLI::App* list = nullptr;
  CLI::App* stop = nullptr;
  CLI::App* logs = nullptr;
  bool all = false, json = false;  ///< list --all, --json
  std::string run, module;         ///< stop RUN, logs RUN MODULE
  double stopTimeoutSeconds = 30;  ///< stop --timeout
  bool follow = false;             ///< logs --follow
};

/// Adds `list`, `stop` and `logs` to `cli`, their options held by `into`.
void addRunsCommands(CLI::App& cli, RunsCommands& into);

/// Runs the one of them that was parsed and returns its exit status; nullopt if none was.
std::optional<int> runRunsCommand(const RunsCommands& commands);

}  // namespace vrflow::cli
