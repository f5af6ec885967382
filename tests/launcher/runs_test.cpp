// The registry of runs (docs/operations.md) through the real `vrflow` binary: `vrflow list`,
// `stop`, `monitor` and `logs` on plain runs and on a 3-host local launch, runs killed with
// SIGKILL shown as lost, ambiguous and unknown ids.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

using nlohmann::json;

std::string pipelineFile() {
  return sourceDir() + "/examples/pipeline/pipeline.xml";
}

std::string threeHostsFile() {
  return sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
}

// A run in the background, from start to end, on a thread of the test.
class Background {
 public:
  explicit Background(std::vector<std::string> args)
      : thread_([this, args] { result_ = runVrflow(args, 120); }) {}
  ~Background() {
    if (thread_.joinable()) thread_.join();
  }
  const CommandResult& result() {
    if (thread_.joinable()) thread_.join();
    return result_;
  }

 private:
  CommandResult result_;
  std::thread thread_;
};

// XDG_RUNTIME_DIR and XDG_STATE_HOME in folders of this test's own: its registry holds only the
// runs it starts.
class RunsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* name : {"XDG_RUNTIME_DIR", "XDG_STATE_HOME"}) {
      const char* previous = std::getenv(name);
      saved_.emplace_back(name, previous ? std::optional<std::string>(previous) : std::nullopt);
    }
    mkdir(dir.file("runtime").c_str(), 0700);
    setenv("XDG_RUNTIME_DIR", dir.file("runtime").c_str(), 1);
    setenv("XDG_STATE_HOME", dir.file("state").c_str(), 1);
  }
  void TearDown() override {
    for (const auto& [name, value] : saved_) {
      if (value) {
        setenv(name.c_str(), value->c_str(), 1);
      } else {
        unsetenv(name.c_str());
      }
    }
    // A run killed with SIGKILL: its modules die with it and come back to this test (a
    // subreaper) to be reaped; nothing may still run.
    for (const auto& left : leftoverProcesses()) {
      EXPECT_NE(left.find("(reaped)"), std::string::npos) << "still running: " << left;
    }
    EXPECT_TRUE(vrflowShmEntries().empty());
  }

  // `vrflow list --json [--all]`.
  json list(bool all = false) {
    const auto shown = runVrflow(all ? std::vector<std::string>{"list", "--json", "--all"}
                                     : std::vector<std::string>{"list", "--json"},
                                 30);
    EXPECT_EQ(shown.exitCode, 0) << shown.err;
    return json::parse(shown.out, nullptr, false);
  }

  // Waits until `count` runs are running and each has two statistics snapshots (a rate);
  // their records.
  json waitForRunning(std::size_t count) {
    json runs;
    for (int i = 0; i < 200; ++i) {
      runs = list();
      bool ready = runs.is_array() && runs.size() == count;
      for (const auto& r : ready ? runs : json::array()) {
        ready = ready && r["state"] == "running" && r["rate"].get<double>() > 0;
      }
      if (ready) return runs;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ADD_FAILURE() << count << " runs never ran; last list: " << runs.dump();
    return json::array();
  }

  // The folders in the runtime registry (running, or lost and not yet seen).
  std::string registered() {
    return runCommand({"/bin/sh", "-c", "ls -A '" + dir.file("runtime/vrflow/runs") + "'"}).out;
  }

  TempDir dir;

 private:
  std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

// What a module of the run "wrote" to its log (the test writes it: this part only reads logs).
void appendLog(const std::string& logDir, const std::string& module, const std::string& text) {
  std::filesystem::create_directories(logDir);
  std::ofstream(logDir + "/" + module + ".log", std::ios::app) << text;
}

TEST_F(RunsTest, APlainRunIsListedMonitoredShownAndStopped) {
  Background run({"run", pipelineFile(), "--timeout", "60"});
  const json running = waitForRunning(1);
  ASSERT_EQ(running.size(), 1u);
  const json& r = running[0];
  const std::string id = r["id"];
  EXPECT_EQ(id.rfind("pipeline-", 0), 0u) << id;
  EXPECT_EQ(r["kind"], "run");
  EXPECT_EQ(r["application"], "pipeline");
  EXPECT_EQ(r["hosts"], json::array({"local"}));
  EXPECT_GT(r["rate"].get<double>(), 0.0);

  const auto table = runVrflow({"list"}, 30);
  EXPECT_NE(table.out.find(id), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("running"), std::string::npos) << table.out;

  // The monitor: by a prefix of the id, and with no id (the only running run).
  for (const std::string& which : {id.substr(0, 12), std::string()}) {
    const auto shown =
        runVrflow(which.empty() ? std::vector<std::string>{"monitor", "--once"}
                                : std::vector<std::string>{"monitor", which, "--once"},
                  30);
    EXPECT_EQ(shown.exitCode, 0) << shown.err;
    for (const char* text :
         {"chain", "springs", "gravity", "relay", "recorder", "relay.out -> recorder.in", "IT/S"}) {
      EXPECT_NE(shown.out.find(text), std::string::npos) << text << " missing:\n" << shown.out;
    }
  }

  const std::string logDir = r["log_dir"];
  appendLog(logDir, "springs", "stiffness 400\nsettled\n");
  appendLog(logDir, "recorder", "writing out/trajectory.csv\n");
  const auto springs = runVrflow({"logs", id, "springs"}, 30);
  EXPECT_EQ(springs.exitCode, 0) << springs.err;
  EXPECT_EQ(springs.out, "stiffness 400\nsettled\n");
  const auto all = runVrflow({"logs", id}, 30);
  // The modules' logs in file order, then the runtime's own (vrflow.log, written by the run).
  EXPECT_EQ(all.out.rfind("[springs] stiffness 400\n[springs] settled\n[recorder] writing "
                          "out/trajectory.csv\n[vrflow] ",
                          0),
            0u)
      << all.out;
  EXPECT_NE(all.out.find("vrflow: run " + id + ", logs in " + logDir + "\n"), std::string::npos)
      << all.out;

  const auto stopped = runVrflow({"stop", id.substr(0, 10)}, 60);
  EXPECT_EQ(stopped.exitCode, 0) << stopped.err;
  EXPECT_NE(stopped.out.find("run " + id + " stopped: run ended: interrupted (exit 130)"),
            std::string::npos)
      << stopped.out;
  EXPECT_EQ(run.result().exitCode, 130) << run.result().err;

  // Ended: no longer running, kept with its outcome, its logs still readable.
  EXPECT_EQ(list(), json::array());
  EXPECT_EQ(registered(), "");
  const json ended = list(/*all=*/true);
  ASSERT_EQ(ended.size(), 1u) << ended.dump();
  EXPECT_EQ(ended[0]["state"], "interrupted");
  EXPECT_EQ(ended[0]["end"]["exit_code"], 130);
  EXPECT_EQ(runVrflow({"logs", id, "springs"}, 30).out, "stiffness 400\nsettled\n");
  // With no run going on, `logs` shows the last one that ran.
  const auto last = runVrflow({"logs"}, 30);
  EXPECT_EQ(last.exitCode, 0) << last.err;
  EXPECT_EQ(last.out.rfind("[springs] stiffness 400\n", 0), 0u) << last.out;
  const auto again = runVrflow({"stop", id}, 30);
  EXPECT_EQ(again.exitCode, 1);
  EXPECT_NE(again.err.find("has already ended (interrupted)"), std::string::npos) << again.err;
}

TEST_F(RunsTest, AThreeHostLaunchIsListedMonitoredShownAndStopped) {
  Background launch({"launch", threeHostsFile(), "--timeout", "60"});
  const json running = waitForRunning(1);
  ASSERT_EQ(running.size(), 1u);
  const std::string id = running[0]["id"];
  EXPECT_EQ(running[0]["kind"], "launch");
  EXPECT_EQ(running[0]["hosts"], json::array({"a", "b", "c"}));

  // Every host's modules and the links between hosts, once each host has sent statistics.
  std::string seen;
  for (int i = 0; i < 100; ++i) {
    seen = runVrflow({"monitor", id, "--once"}, 30).out;
    if (seen.find("LINKS") != std::string::npos && seen.find("gravity") != std::string::npos &&
        seen.find("springs") != std::string::npos && seen.find("chain") != std::string::npos) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (const char* text :
       {"a        chain", "b        springs", "c        gravity", "LINKS", "launcher pid"}) {
    EXPECT_NE(seen.find(text), std::string::npos) << text << " missing:\n" << seen;
  }

  appendLog(running[0]["log_dir"], "gravity", "g = 9.81\n");
  EXPECT_EQ(runVrflow({"logs", id, "gravity"}, 30).out, "g = 9.81\n");

  const auto stopped = runVrflow({"stop"}, 60);  // the only running run
  EXPECT_EQ(stopped.exitCode, 0) << stopped.err;
  EXPECT_NE(stopped.out.find("interrupted (exit 130)"), std::string::npos) << stopped.out;
  EXPECT_EQ(launch.result().exitCode, 130) << launch.result().err;
  EXPECT_EQ(registered(), "");
  const json ended = list(/*all=*/true);
  ASSERT_EQ(ended.size(), 1u);
  EXPECT_EQ(ended[0]["state"], "interrupted");
  EXPECT_EQ(runVrflow({"logs", id.substr(0, 14), "gravity"}, 30).out, "g = 9.81\n");
}

TEST_F(RunsTest, AFollowerPrintsALaunchsEventsAsTheyComeUntilItsEnd) {
  Background launch({"launch", threeHostsFile(), "--timeout", "60"});
  const json running = waitForRunning(1);
  ASSERT_EQ(running.size(), 1u);
  const std::string id = running[0]["id"];
  Background follower({"monitor", id.substr(0, 12), "--follow-events"});
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // statistics of every host
  EXPECT_EQ(runVrflow({"stop", id}, 60).exitCode, 0);
  const auto& followed = follower.result();
  EXPECT_EQ(followed.exitCode, 0) << followed.err;
  EXPECT_EQ(launch.result().exitCode, 130);

  // The same event lines as `--events` (docs/events.md): started, each host's stats, the end.
  std::vector<json> events;
  std::istringstream lines(followed.out);
  for (std::string line; std::getline(lines, line);) events.push_back(json::parse(line));
  ASSERT_GE(events.size(), 5u) << followed.out;
  EXPECT_EQ(events.front()["event"], "started");
  EXPECT_EQ(events.front()["run"], id);
  EXPECT_EQ(events.front()["hosts"].size(), 3u);
  EXPECT_EQ(events.front()["modules"].size(), 5u);
  std::set<std::string> statsHosts;
  double time = 0;
  for (const auto& event : events) {
    EXPECT_GE(event["time"].get<double>(), time) << event.dump();
    time = event["time"].get<double>();
    if (event["event"] == "stats") {
      statsHosts.insert(event.value("host", ""));
      EXPECT_TRUE(event["modules"].is_array());
    }
  }
  EXPECT_EQ(statsHosts, (std::set<std::string>{"a", "b", "c"})) << followed.out;
  EXPECT_EQ(events.back()["event"], "end");
  EXPECT_EQ(events.back()["exit_code"], 130);
  EXPECT_EQ(events.back()["status"], "interrupted");

  // An ended run has no events to follow.
  const auto ended = runVrflow({"monitor", id, "--follow-events"}, 30);
  EXPECT_EQ(ended.exitCode, 1);
  EXPECT_NE(ended.err.find("has ended"), std::string::npos) << ended.err;
}

TEST_F(RunsTest, ARunStuckInAModuleIsStoppedAllTheSame) {
  // The worker sleeps 10 s per message: it never answers the stop request, so the run's stop
  // ends it (SIGTERM, then SIGKILL) after its grace time.
  const auto file = dir.write(
      "stuck.xml", appXml(moduleXml("feed", "core/source") +
                              moduleXml("stuck", "testing/slow", paramXml("delay-ms", "10000")),
                          "", connectXml("feed.out", "stuck.in")));
  Background run({"run", file, "--timeout", "60"});
  json running;
  for (int i = 0; i < 200 && running.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    running = list();
  }
  ASSERT_EQ(running.size(), 1u);
  const auto stopped = runVrflow({"stop", running[0]["id"]}, 60);
  EXPECT_EQ(stopped.exitCode, 0) << stopped.err;
  EXPECT_NE(stopped.out.find("interrupted (exit 130)"), std::string::npos) << stopped.out;
  EXPECT_EQ(run.result().exitCode, 130) << run.result().err;
  EXPECT_EQ(registered(), "");
}

TEST_F(RunsTest, ARunKilledWithSigkillIsShownLostOnceThenKeptAsLost) {
  const auto killed = runVrflow({"run", pipelineFile(), "--timeout", "60"}, 90, 3, SIGKILL);
  EXPECT_EQ(killed.exitCode, 128 + SIGKILL);
  EXPECT_NE(registered(), "") << "the run registered nothing";
  const auto shown = runVrflow({"list"}, 30);
  EXPECT_EQ(shown.exitCode, 0) << shown.err;
  EXPECT_NE(shown.out.find("lost"), std::string::npos) << shown.out;
  // Cleaned from the runtime folder, kept with the ended runs as lost.
  EXPECT_EQ(registered(), "");
  EXPECT_EQ(list(), json::array());
  const json all = list(/*all=*/true);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0]["state"], "lost");
  EXPECT_NE(all[0]["end"]["error"].get<std::string>().find("ended without finishing the run"),
            std::string::npos);
  const auto stop = runVrflow({"stop", all[0]["id"]}, 30);
  EXPECT_EQ(stop.exitCode, 1);
  EXPECT_NE(stop.err.find("has already ended (lost)"), std::string::npos) << stop.err;
}

TEST_F(RunsTest, AmbiguousAndUnknownIdsAreRefusedNamingTheCandidates) {
  const auto none = runVrflow({"stop"}, 30);
  EXPECT_EQ(none.exitCode, 1);
  EXPECT_NE(none.err.find("no run is running"), std::string::npos) << none.err;

  Background first({"run", pipelineFile(), "--timeout", "60"});
  Background second({"run", pipelineFile(), "--timeout", "60"});
  const json running = waitForRunning(2);
  ASSERT_EQ(running.size(), 2u);
  const std::string a = running[0]["id"], b = running[1]["id"];

  for (const auto& command : std::vector<std::vector<std::string>>{
           {"stop", "pipeline"}, {"monitor", "pipeline", "--once"}, {"logs", "pipe"}}) {
    const auto refused = runVrflow(command, 30);
    EXPECT_EQ(refused.exitCode, 1) << command[0];
    EXPECT_NE(refused.err.find("is the start of several runs' ids"), std::string::npos)
        << refused.err;
    EXPECT_NE(refused.err.find(a), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find(b), std::string::npos) << refused.err;
  }
  const auto several = runVrflow({"monitor", "--once"}, 30);
  EXPECT_EQ(several.exitCode, 1);
  EXPECT_NE(several.err.find("2 runs are running: "), std::string::npos) << several.err;
  const auto unknown = runVrflow({"stop", "nosuchrun"}, 30);
  EXPECT_EQ(unknown.exitCode, 1);
  EXPECT_NE(unknown.err.find("no run 'nosuchrun'; the runs are: "), std::string::npos)
      << unknown.err;
  EXPECT_NE(unknown.err.find(a), std::string::npos) << unknown.err;
  const auto badModule = runVrflow({"logs", a, "nosuchmodule"}, 30);
  EXPECT_EQ(badModule.exitCode, 1);
  EXPECT_NE(badModule.err.find("has no module 'nosuchmodule' (its modules: chain,springs,"),
            std::string::npos)
      << badModule.err;

  EXPECT_EQ(runVrflow({"stop", a}, 60).exitCode, 0);
  EXPECT_EQ(runVrflow({"stop", b}, 60).exitCode, 0);
  EXPECT_EQ(first.result().exitCode, 130);
  EXPECT_EQ(second.result().exitCode, 130);
}

TEST_F(RunsTest, OnlyTheLastFiftyEndedRunsAreKept) {
  const auto first = runVrflow({"run", pipelineFile(), "-n", "5"}, 60);
  ASSERT_EQ(first.exitCode, 0) << first.err;
  const json ended = list(/*all=*/true);
  ASSERT_EQ(ended.size(), 1u);
  // 55 older runs, as the first left its record (copies of it, started earlier).
  const std::string runs = dir.file("state/vrflow/runs/");
  const std::string id = ended[0]["id"];
  for (int i = 0; i < 55; ++i) {
    const std::string older = "older-" + std::to_string(100 + i);
    std::filesystem::copy(runs + id, runs + older);
    json record = json::parse(readFile(runs + older + "/run.json"));
    record["id"] = older;
    record["start_time"] = record["start_time"].get<int64_t>() - 1000 + i;
    std::ofstream(runs + older + "/run.json") << record.dump();
  }
  const auto last = runVrflow({"run", pipelineFile(), "-n", "5"}, 60);
  ASSERT_EQ(last.exitCode, 0) << last.err;
  const json kept = list(/*all=*/true);
  ASSERT_EQ(kept.size(), 50u);
  // The oldest went: the 7 first copies; the two real runs are the newest.
  EXPECT_EQ(kept[0]["id"], "older-107");
  EXPECT_EQ(kept[48]["id"], id);
  EXPECT_EQ(kept[49]["state"], "ok");
}

TEST_F(RunsTest, LogsFollowPrintsNewLinesAndEndsWithTheRun) {
  Background run({"run", pipelineFile(), "--timeout", "60"});
  const json running = waitForRunning(1);
  ASSERT_EQ(running.size(), 1u);
  const std::string id = running[0]["id"], logDir = running[0]["log_dir"];
  appendLog(logDir, "relay", "first\n");
  CommandResult followed;
  std::thread follower([&] { followed = runVrflow({"logs", id, "--follow"}, 90); });
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  appendLog(logDir, "relay", "second\n");
  appendLog(logDir, "chain", "last words");  // no newline: printed when the run ends
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(runVrflow({"stop", id}, 60).exitCode, 0);
  follower.join();  // returns only once the run has ended
  EXPECT_EQ(run.result().exitCode, 130) << run.result().err;
  EXPECT_EQ(followed.exitCode, 0) << followed.err;
  // Each file's lines in order; the files' lines interleave as they were seen. The runtime's
  // own lines (vrflow.log) come too: the stop is among them.
  std::string modules, runtime;
  std::istringstream lines(followed.out);
  for (std::string line; std::getline(lines, line);) {
    (line.rfind("[vrflow] ", 0) == 0 ? runtime : modules) += line + "\n";
  }
  EXPECT_NE(modules.find("[relay] first\n[relay] second\n"), std::string::npos) << followed.out;
  EXPECT_NE(modules.find("[chain] last words\n"), std::string::npos) << followed.out;
  EXPECT_EQ(modules.size(),
            std::string("[relay] first\n[relay] second\n[chain] last words\n").size())
      << followed.out;
  EXPECT_NE(runtime.find("interrupted by SIGTERM"), std::string::npos) << followed.out;
  // On a run that has ended: prints and exits.
  const auto after = runVrflow({"logs", id, "relay", "--follow"}, 30);
  EXPECT_EQ(after.exitCode, 0);
  EXPECT_EQ(after.out, "first\nsecond\n");
}

}  // namespace
}  // namespace vrflow::testing
