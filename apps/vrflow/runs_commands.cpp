// `vrflow list`, `vrflow stop` and `vrflow logs` (runs_commands.hpp).
#include "runs_commands.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "vrflow/run/registry.hpp"

namespace vrflow::cli {
namespace {

using nlohmann::json;

std::string localTime(int64_t seconds) {
  const auto t = static_cast<std::time_t>(seconds);
  std::tm local{};
  localtime_r(&t, &local);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &local);
  return text;
}

std::string joined(const std::vector<std::string>& items) {
  std::string text;
  for (const auto& item : items) text += (text.empty() ? "" : ",") + item;
  return text;
}

// "120" or "120/500" with -n 500.
std::string iterationText(const run::RunRecord& r) {
  std::string text = std::to_string(r.state.iterations());
  if (r.identity.iterations > 0) text += "/" + std::to_string(r.identity.iterations);
  return text;
}

int listRuns(bool all, bool asJson) {
  auto runs = run::listRuns(all);
  if (!runs) {
    std::fprintf(stderr, "vrflow list: %s\n", runs.error().message.c_str());
    return 1;
  }
  if (asJson) {
    auto list = json::array();
    for (const auto& r : *runs) {
      list.push_back({{"id", r.identity.id},
                      {"kind", r.identity.kind},
                      {"application", r.identity.application},
                      {"file", r.identity.file},
                      {"hosts", r.identity.hosts},
                      {"pid", r.identity.pid},
                      {"start_time", r.identity.startTime},
                      {"state", r.stateWord()},
                      {"iterations", r.state.iterations()},
                      {"iteration_target", r.identity.iterations},
                      {"rate", r.running ? r.state.rate() : 0.0},
                      {"log_dir", r.identity.logDir},
                      {"end", json::parse(r.state.toJson())["end"]}});
    }
    std::printf("%s\n", list.dump().c_str());
    return 0;
  }
  if (runs->empty()) {
    std::fprintf(stderr, "vrflow list: no run is %s\n",
                 all ? "registered" : "running (`vrflow list --all` shows the ended ones)");
    return 0;
  }
  std::printf("%-40s %-16s %-16s %-19s %-11s %14s %10s\n", "RUN", "APPLICATION", "HOSTS", "STARTED",
              "STATE", "ITERATION", "IT/S");
  for (const auto& r : *runs) {
    std::printf("%-40s %-16s %-16s %-19s %-11s %14s %10.1f\n", r.identity.id.c_str(),
                r.identity.application.c_str(), joined(r.identity.hosts).c_str(),
                localTime(r.identity.startTime).c_str(), r.stateWord().c_str(),
                iterationText(r).c_str(), r.running ? r.state.rate() : 0.0);
  }
  return 0;
}

int stopRun(const std::string& prefix, double timeoutSeconds) {
  auto found = run::findRun(prefix, /*all=*/true);
  if (!found) {
    std::fprintf(stderr, "vrflow stop: %s\n", found.error().message.c_str());
    return 1;
  }
  const run::RunIdentity& who = found->identity;
  if (!found->running) {
    std::fprintf(stderr, "vrflow stop: run '%s' has already ended (%s)\n", who.id.c_str(),
                 found->stateWord().c_str());
    return 1;
  }
  // SIGTERM is an orderly stop, as Ctrl-C: the run stops its modules (or the launch its hosts),
  // writes its report and ends.
  if (kill(who.pid, SIGTERM) != 0) {
    std::fprintf(stderr, "vrflow stop: cannot signal run '%s' (pid %d): %s\n", who.id.c_str(),
                 static_cast<int>(who.pid), std::strerror(errno));
    return 1;
  }
  const auto begin = std::chrono::steady_clock::now();
  while (run::processRuns(who.pid, who.pidStart)) {
    if (std::chrono::steady_clock::now() - begin > std::chrono::duration<double>(timeoutSeconds)) {
      std::fprintf(stderr,
                   "vrflow stop: run '%s' did not stop within %g s (pid %d still runs; "
                   "`kill -KILL %d` ends it at once)\n",
                   who.id.c_str(), timeoutSeconds, static_cast<int>(who.pid),
                   static_cast<int>(who.pid));
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  auto ended = run::findRun(who.id, /*all=*/true);
  std::printf("run %s stopped: %s\n", who.id.c_str(),
              ended ? ended->state.endLine().c_str() : "(its record is gone)");
  return 0;
}

// One log file followed from where it was last read.
struct LogTail {
  std::string prefix;  ///< "[module] ", or empty for a single log
  std::string path;
  off_t offset = 0;
  std::string partial;  ///< the start of a line not yet ended

  // Prints the whole lines added since the last call (and, with `flush`, a last line without
  // its newline).
  void print(bool flush) {
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd >= 0) {
      struct stat info {};
      if (fstat(fd, &info) == 0 && info.st_size < offset) offset = 0;  // truncated: again
      char buffer[65536];
      ssize_t n = 0;
      while ((n = pread(fd, buffer, sizeof buffer, offset)) > 0) {
        offset += n;
        partial.append(buffer, static_cast<std::size_t>(n));
        std::size_t start = 0;
        for (std::size_t end; (end = partial.find('\n', start)) != std::string::npos;
             start = end + 1) {
          std::fputs((prefix + partial.substr(start, end + 1 - start)).c_str(), stdout);
        }
        partial.erase(0, start);
      }
      close(fd);
    }
    if (flush && !partial.empty()) {
      std::fputs((prefix + partial + "\n").c_str(), stdout);
      partial.clear();
    }
    std::fflush(stdout);
  }
};

int showLogs(const std::string& prefix, const std::string& module, bool follow) {
  auto found = run::findRun(prefix, /*all=*/true);
  if (!found && prefix.empty()) {
    // No run going on: the last one that ran (what a person looks at after a run failed).
    auto runs = run::listRuns(/*all=*/true);
    const bool noneRunning =
        runs && std::none_of(runs->begin(), runs->end(), [](const auto& r) { return r.running; });
    if (noneRunning && !runs->empty()) found = runs->back();
  }
  if (!found) {
    std::fprintf(stderr, "vrflow logs: %s\n", found.error().message.c_str());
    return 1;
  }
  const run::RunIdentity& who = found->identity;
  if (who.logDir.empty()) {
    std::fprintf(stderr, "vrflow logs: run '%s' has no log folder\n", who.id.c_str());
    return 1;
  }
  std::vector<LogTail> tails;
  if (!module.empty()) {
    bool known = false;
    for (const auto& m : who.modules) known = known || m == module;
    if (!known && module != "vrflow") {
      std::fprintf(stderr, "vrflow logs: run '%s' has no module '%s' (its modules: %s)\n",
                   who.id.c_str(), module.c_str(), joined(who.modules).c_str());
      return 1;
    }
    tails.push_back({"", who.logDir + "/" + module + ".log", 0, {}});
  } else {
    for (const auto& m : who.modules)
      tails.push_back({"[" + m + "] ", who.logDir + "/" + m + ".log", 0, {}});
    tails.push_back({"[vrflow] ", who.logDir + "/vrflow.log", 0, {}});
  }
  struct stat info {};
  if (!follow || !found->running) {
    if (stat(who.logDir.c_str(), &info) != 0) {
      std::fprintf(stderr, "vrflow logs: the log folder '%s' of run '%s' does not exist\n",
                   who.logDir.c_str(), who.id.c_str());
      return 1;
    }
    if (!module.empty() && stat(tails.front().path.c_str(), &info) != 0) {
      std::fprintf(stderr, "vrflow logs: no log '%s' (module '%s' of run '%s' wrote none)\n",
                   tails.front().path.c_str(), module.c_str(), who.id.c_str());
      return 1;
    }
  }
  // --follow: until the run ends, then what it wrote last.
  while (follow && run::processRuns(who.pid, who.pidStart)) {
    for (auto& tail : tails) tail.print(false);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  for (auto& tail : tails) tail.print(true);
  return 0;
}

}  // namespace

void addRunsCommands(CLI::App& cli, RunsCommands& into) {
  into.list = cli.add_subcommand("list", "List the running runs and launches of this user");
  into.list->add_flag("--all", into.all, "Also the ended runs (the last 50)");
  into.list->add_flag("--json", into.json, "Print them as a JSON array");

  into.stop = cli.add_subcommand("stop", "Stop a run in order (as Ctrl-C) and wait for its end");
  into.stop->add_option("RUN", into.run,
                        "Run id, or any unique start of it (default: the only running run)");
  into.stop
      ->add_option("--timeout", into.stopTimeoutSeconds,
                   "Give up waiting after this long (seconds; exit 1 if it still runs)")
      ->check(CLI::PositiveNumber);

  into.logs = cli.add_subcommand("logs", "Print the logs of a run (or of one of its modules)");
  into.logs->add_option("RUN", into.run,
                        "Run id, or any unique start of it (default: the only running run)");
  into.logs->add_option("MODULE", into.module, "Only this module's log ('vrflow': the runtime's)");
  into.logs->add_flag("--follow,-f", into.follow, "Keep printing new lines until the run ends");
}

std::optional<int> runRunsCommand(const RunsCommands& commands) {
  if (commands.list->parsed()) return listRuns(commands.all, commands.json);
  if (commands.stop->parsed()) return stopRun(commands.run, commands.stopTimeoutSeconds);
  if (commands.logs->parsed()) return showLogs(commands.run, commands.module, commands.follow);
  return std::nullopt;
}

}  // namespace vrflow::cli
