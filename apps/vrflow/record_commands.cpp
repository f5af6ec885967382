// `vrflow record`, `vrflow replay` and `vrflow inspect` (record_commands.hpp).
#include "record_commands.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

#include "vrflow/app/catalog.hpp"
#include "vrflow/app/graph.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/record/connections_param.hpp"
#include "vrflow/record/reader.hpp"
#include "vrflow/record/summary.hpp"
#include "vrflow/run/log.hpp"
#include "vrflow/run/prepare.hpp"
#include "vrflow/run/run_folders.hpp"
#include "vrflow/run/runner.hpp"

namespace vrflow::cli {
namespace {

// At most this many diagnostics are printed, as `vrflow run` does.
constexpr std::size_t kMaxPrintedDiagnostics = 20;
// The replay module's ports: in0..in7, out0..out7 (record/vrflow-package.xml).
constexpr std::size_t kReplayPorts = 8;

// Prints "vrflow COMMAND: why" and returns the status of a bad command line or file.
int refuse(const char* command, const std::string& why) {
  std::fprintf(stderr, "vrflow %s: %s\n", command, why.c_str());
  return run::kExitInvalid;
}

struct Loaded {
  app::Application application;
  app::Catalog catalog;
};

// The application ready to run, as `vrflow run` prepares it (its problems printed).
std::optional<Loaded> load(const RecordCommands& c) {
  run::Prepared prepared = run::prepare({.file = c.appFile,
                                         .packageDirs = c.packageDirs,
                                         .compositeDirs = {},
                                         .overrides = c.overrides,
                                         .validate = true,
                                         .files = app::ModuleFileChecks{.executables = true},
                                         .program = "vrflow"});
  run::printProblems(prepared, kMaxPrintedDiagnostics);
  if (!prepared.ok()) return std::nullopt;
  return Loaded{std::move(*prepared.application), std::move(*prepared.catalog)};
}

// `base`, or `base-N` for the first N that no module or filter of `application` has.
std::string unusedId(const app::Application& application, const std::string& base) {
  std::string id = base;
  for (int n = 1; app::findModule(application, id) || app::findFilter(application, id); ++n) {
    id = base + "-" + std::to_string(n);
  }
  return id;
}

// The output ports of `module`, in manifest order (beginIt/endIt left out).
std::vector<const app::PortSpec*> outputsOf(const app::Catalog& catalog, const app::Module& module,
                                            std::vector<app::PortSpec>& storage) {
  storage = catalog.portsOf(module);
  std::vector<const app::PortSpec*> outputs;
  for (const auto& p : storage) {
    if (!p.isInput && p.name != app::kEndItPort) outputs.push_back(&p);
  }
  return outputs;
}

std::string listed(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& n : names) text += (text.empty() ? "" : ", ") + n;
  return text.empty() ? "none" : text;
}

app::Param param(std::string name, std::string value) {
  app::Param p;
  p.name = std::move(name);
  p.value = std::move(value);
  return p;
}

app::Connection connection(std::string fromNode, std::string fromPort, std::string toNode,
                           std::string toPort) {
  app::Connection c;
  c.from = {std::move(fromNode), std::move(fromPort)};
  c.to = {std::move(toNode), std::move(toPort)};
  return c;
}

// The recorded connections that `names` (MODULE.PORT) stand for, or why one is not an output.
Result<std::vector<record::RecordedConnection>> recordedConnections(
    const app::Application& application, const app::Catalog& catalog,
    const std::vector<std::string>& names) {
  std::vector<record::RecordedConnection> connections;
  for (const auto& name : names) {
    const auto dot = name.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == name.size()) {
      return makeError("--connections: '" + name + "' is not MODULE.PORT");
    }
    const std::string id = name.substr(0, dot), port = name.substr(dot + 1);
    const app::Module* module = app::findModule(application, id);
    if (module == nullptr) {
      return makeError("--connections: '" + name + "': " + application.file + " has no module '" +
                       id + "'" +
                       (app::findFilter(application, id) ? " (it is a filter: record the output "
                                                           "of a module)"
                                                         : ""));
    }
    std::vector<app::PortSpec> storage;
    std::vector<std::string> outputNames;
    const app::PortSpec* found = nullptr;
    for (const app::PortSpec* p : outputsOf(catalog, *module, storage)) {
      outputNames.push_back(p->name);
      if (p->name == port) found = p;
    }
    if (found == nullptr) {
      return makeError("--connections: '" + name + "': module '" + id + "' (" + module->package +
                       "/" + module->type + ") has no output '" + port +
                       "' (its outputs: " + listed(outputNames) + ")");
    }
    record::RecordedConnection c{id, port, found->data};
    if (std::find(connections.begin(), connections.end(), c) != connections.end()) {
      return makeError("--connections: '" + name + "' is listed twice");
    }
    for (const auto& other : connections) {
      if (other.module == id) {
        return makeError("--connections: '" + other.name() + "' and '" + name +
                         "' come from the same module: the recorder tells connections apart by "
                         "the module that sent each message (record them in two runs)");
      }
    }
    connections.push_back(std::move(c));
  }
  return connections;
}

// Adds the recorder (and a multiplex filter in front of it for several connections).
std::string attachRecorder(app::Application& application,
                           const std::vector<record::RecordedConnection>& connections,
                           const std::string& file, int level) {
  const std::string host = app::findModule(application, connections.front().module)->host;
  const std::string id = unusedId(application, "record");
  app::Module recorder;
  recorder.id = id;
  recorder.package = "record";
  recorder.type = "record";
  recorder.host = host;
  recorder.params = {param("file", file),
                     param("connections", record::connectionsParam(connections)),
                     param("level", std::to_string(level))};
  application.modules.push_back(std::move(recorder));
  if (connections.size() == 1) {
    application.connections.push_back(
        connection(connections[0].module, connections[0].port, id, "in"));
    return id;
  }
  app::Filter mux;
  mux.id = unusedId(application, "record-multiplex");
  mux.type = "multiplex";
  mux.host = host;
  mux.params = {param("inputs", std::to_string(connections.size())), param("renumber", "false")};
  for (std::size_t i = 0; i < connections.size(); ++i) {
    application.connections.push_back(
        connection(connections[i].module, connections[i].port, mux.id, "in" + std::to_string(i)));
  }
  application.connections.push_back(connection(mux.id, "out", id, "in"));
  application.filters.push_back(std::move(mux));
  return id;
}

// Puts a replay of its recorded outputs in place of module `id`: same id, host and
// connections, its inputs and outputs renamed in0.. and out0.. (docs/recording.md).
Status replaceByReplay(app::Application& application, const record::RecordingReader& reader,
                       const std::string& id, const std::string& file, const std::string& pace) {
  app::Module* module = app::findModule(application, id);
  if (module == nullptr)
    return makeError("--replace: " + application.file + " has no module '" + id + "'");
  std::vector<std::string> recorded, all;
  for (const auto& c : reader.connections()) {
    all.push_back(c.name());
    if (c.module == id) recorded.push_back(c.port);
  }
  if (recorded.empty()) {
    return makeError("--replace: '" + reader.path() + "' holds no output of module '" + id +
                     "' (it holds: " + listed(all) + ")");
  }
  if (recorded.size() > kReplayPorts) {
    return makeError("--replace: module '" + id + "' has more than 8 recorded outputs");
  }
  std::map<std::string, std::string, std::less<>> inputs, outputs;
  for (std::size_t i = 0; i < recorded.size(); ++i)
    outputs[recorded[i]] = "out" + std::to_string(i);
  for (const auto& c : application.connections) {
    if (c.from.node == id && c.from.port != app::kEndItPort && !outputs.contains(c.from.port)) {
      return makeError("--replace: output '" + id + "." + c.from.port + "' is connected in " +
                       application.file + " but '" + reader.path() +
                       "' does not hold it (record it too: --connections " + id + "." +
                       c.from.port + ")");
    }
    if (c.to.node == id && c.to.port != app::kBeginItPort && !inputs.contains(c.to.port)) {
      if (inputs.size() == kReplayPorts) {
        return makeError("--replace: module '" + id + "' has more than 8 connected inputs");
      }
      inputs[c.to.port] = "in" + std::to_string(inputs.size());
    }
  }
  for (auto& c : application.connections) {
    if (c.from.node == id && outputs.contains(c.from.port)) c.from.port = outputs[c.from.port];
    if (c.to.node == id && inputs.contains(c.to.port)) c.to.port = inputs[c.to.port];
  }
  std::vector<app::InputConfig> configs;
  for (auto config : module->inputs) {
    if (const auto renamed = inputs.find(config.port); renamed != inputs.end()) {
      config.port = renamed->second;
      configs.push_back(config);
    } else if (config.port == app::kBeginItPort) {
      configs.push_back(config);
    }
  }
  std::string ports;
  for (const auto& p : recorded) ports += (ports.empty() ? "" : " ") + p;
  module->inputs = std::move(configs);
  module->package = "record";
  module->type = "replay";
  module->params = {param("file", file), param("module", id), param("outputs", ports),
                    param("pace", pace)};
  return {};
}

// Validates the rewritten application; false (problems printed) when it cannot run.
bool stillValid(const char* command, const app::Application& application,
                const app::Catalog& catalog) {
  bool ok = true;
  for (const auto& d : app::validate(application, catalog)) {
    if (d.severity != app::Diagnostic::Error) continue;
    std::fprintf(stderr, "vrflow %s: the rewritten network: %s\n", command,
                 app::formatDiagnostic(d).c_str());
    ok = false;
  }
  return ok;
}

// Runs the rewritten application as `vrflow run` would, its logs in a folder of its own.
int runRewritten(const app::Application& application, const app::Catalog& catalog,
                 const RecordCommands& c, run::RunOptions options) {
  options.iterations = c.iterations;
  options.reportPath = c.reportPath;
  options.timeoutSeconds = c.timeoutSeconds;
  options.progress = c.noProgress                 ? run::ProgressMode::Off
                     : isatty(STDERR_FILENO) != 0 ? run::ProgressMode::Live
                                                  : run::ProgressMode::Summary;
  options.runId = run::newRunId(application.name);
  options.logDir = run::defaultLogDirectory(options.runId);
  if (auto made = run::prepareLogDirectory(options.logDir); !made) {
    std::fprintf(stderr, "vrflow: %s\n", made.error().message.c_str());
    return run::kExitInvalid;
  }
  if (auto status = run::setupLogging(run::LogLevel::Info, options.logDir); !status) {
    std::fprintf(stderr, "vrflow: %s\n", status.error().message.c_str());
    return run::kExitInvalid;
  }
  run::logInfo("vrflow: run " + options.runId + ", logs in " + options.logDir);
  const auto outcome = run::runApplication(application, catalog, options);
  if (outcome.exitCode != 0) run::logError("vrflow: " + outcome.error);
  if (!outcome.detail.empty()) run::logError(outcome.detail);
  run::shutdownLogging();
  return outcome.exitCode;
}

int recordRun(RecordCommands& c) {
  auto loaded = load(c);
  if (!loaded) return run::kExitInvalid;
  auto connections = recordedConnections(loaded->application, loaded->catalog, c.connections);
  if (!connections) return refuse("record", connections.error().message);
  if (c.recording.empty()) c.recording = loaded->application.name + ".vrrec";
  const std::string file = std::filesystem::absolute(c.recording).lexically_normal().string();
  // Checked before anything starts: a run must not end unable to write what it recorded.
  const auto folder = std::filesystem::path(file).parent_path();
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error) || std::filesystem::is_directory(file, error)) {
    return refuse("record", "cannot write the recording to '" + c.recording + "': " +
                                (std::filesystem::is_directory(file, error)
                                     ? std::string("it is a folder")
                                     : "folder '" + folder.string() + "' does not exist"));
  }
  // Every module keeps its iteration count; the recorder takes what comes until its inputs end.
  run::RunOptions options;
  if (c.iterations > 0) {
    const auto rates =
        app::iterationRates(loaded->application, app::resolveGraph(loaded->application));
    for (std::size_t m = 0; m < loaded->application.modules.size(); ++m) {
      options.moduleIterations[loaded->application.modules[m].id] = rates[m].scale(c.iterations);
    }
  }
  const std::string recorder = attachRecorder(loaded->application, *connections, file, c.level);
  options.moduleIterations[recorder] = 0;
  if (c.iterations == 0) options.moduleIterations.clear();
  if (!stillValid("record", loaded->application, loaded->catalog)) return run::kExitInvalid;
  const int status = runRewritten(loaded->application, loaded->catalog, c, std::move(options));
  if (status == 0) std::fprintf(stderr, "vrflow record: wrote %s\n", file.c_str());
  return status;
}

int replayRun(RecordCommands& c) {
  // The recording is checked whole first: a bad file is one error before anything starts.
  auto reader = record::RecordingReader::open(c.recording);
  if (!reader) return refuse("replay", reader.error().message);
  if (auto summary = record::summarize(**reader); !summary) {
    return refuse("replay", summary.error().message);
  }
  auto loaded = load(c);
  if (!loaded) return run::kExitInvalid;
  const std::string file = std::filesystem::absolute(c.recording).lexically_normal().string();
  for (const auto& id : c.replaced) {
    if (auto status = replaceByReplay(loaded->application, **reader, id, file, c.pace); !status) {
      return refuse("replay", status.error().message);
    }
  }
  if (!stillValid("replay", loaded->application, loaded->catalog)) return run::kExitInvalid;
  return runRewritten(loaded->application, loaded->catalog, c, {});
}

int inspect(const RecordCommands& c) {
  // A file a recorder is writing ends in a chunk in progress, not a truncation: read what is
  // there.
  auto reader = record::RecordingReader::open(c.recording,
                                              record::RecordingReader::beingWritten(c.recording));
  if (!reader) return refuse("inspect", reader.error().message);
  auto summary = record::summarize(**reader);
  if (!summary) return refuse("inspect", summary.error().message);
  const std::string text =
      c.json ? record::summaryJson(*summary) + "\n" : record::formatSummary(*summary);
  std::fputs(text.c_str(), stdout);
  return 0;
}

// The run options `record` and `replay` share with `vrflow run`.
void addRunOptions(CLI::App& command, RecordCommands& into) {
  command.add_option("APP.xml", into.appFile, "Application file")->required();
  command.add_option("--packages", into.packageDirs, "Extra folder of node packages (repeatable)")
      ->allow_extra_args(false);
  command.add_option("--set", into.overrides, "ID.PARAM=VALUE (repeatable)")
      ->allow_extra_args(false);
  command.add_option("--iterations,-n", into.iterations, "Stop after N iterations of every module");
  command.add_option("--report", into.reportPath, "Write a JSON run report to FILE");
  command.add_option("--timeout", into.timeoutSeconds, "Fail if the run lasts longer (seconds)")
      ->check(CLI::PositiveNumber);
  command.add_flag("--no-progress", into.noProgress, "Show no progress");
}

}  // namespace

void addRecordCommands(CLI::App& cli, RecordCommands& into) {
  into.record = cli.add_subcommand(
      "record", "Run an application with a recorder attached to some outputs (docs/recording.md)");
  addRunOptions(*into.record, into);
  into.record
      ->add_option("--connections", into.connections,
                   "The outputs to record: MODULE.PORT, comma-separated")
      ->required()
      ->delimiter(',');
  into.record->add_option("-o,--output", into.recording,
                          "The recording to write (default: APPLICATION.vrrec here)");
  into.record->add_option("--level", into.level, "zstd compression level")
      ->check(CLI::Range(-7, 19));

  into.replay = cli.add_subcommand(
      "replay", "Run an application with modules replaced by the replay of their recorded outputs");
  into.replay->add_option("FILE", into.recording, "The recording")->required();
  addRunOptions(*into.replay, into);
  into.replay->add_option("--replace", into.replaced, "A module to replace (repeatable)")
      ->required()
      ->allow_extra_args(false);
  into.replay->add_option("--pace", into.pace, "recorded, fast or step")
      ->check(CLI::IsMember({"recorded", "fast", "step"}));

  into.inspect = cli.add_subcommand("inspect", "What a recording holds (as ros2 bag info)");
  into.inspect->add_option("FILE", into.recording, "The recording")->required();
  into.inspect->add_flag("--json", into.json, "One JSON object");
}

std::optional<int> runRecordCommand(RecordCommands& commands) {
  if (commands.record->parsed()) return recordRun(commands);
  if (commands.replay->parsed()) return replayRun(commands);
  if (commands.inspect->parsed()) return inspect(commands);
  return std::nullopt;
}

}  // namespace vrflow::cli
