// `vrflow launch --events`: one stream merged from every host's daemon (docs/events.md).
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// `vrflow launch` of the three-host pipeline for `iterations`, its events written to `events`.
CommandResult launchThreeHosts(const TempDir& dir, int iterations, const std::string& events) {
  return runCommand({"/bin/sh", "-c",
                     "cd " + dir.path() + " && " + binDir() + "/vrflow launch " + sourceDir() +
                         "/examples/pipeline_3hosts/pipeline_3hosts.xml -n " +
                         std::to_string(iterations) + " --events " + events},
                    120);
}

TEST(LaunchEvents, ThreeHostsGiveOneStreamWithEachHostsStatsAndModuleExits) {
  TempDir dir;
  const auto events = dir.file("events.jsonl");
  const auto result = launchThreeHosts(dir, 200, events);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::vector<nlohmann::json> lines;
  std::istringstream in(readFile(events));
  for (std::string line; std::getline(in, line);) {
    auto event = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    ASSERT_TRUE(event.is_object()) << line;
    lines.push_back(std::move(event));
  }
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines.front()["event"], "started");
  EXPECT_EQ(lines.front()["hosts"].size(), 3u);
  std::map<std::string, std::string> hostOf;  // module -> host, as the launch started them
  for (const auto& m : lines.front()["modules"]) hostOf[m["id"]] = m["host"];

  std::set<std::string> statsHosts, exited;
  std::map<std::string, uint64_t> iterations;
  bool links = false;
  int ends = 0, starts = 0;
  for (const auto& e : lines) {
    if (e["event"] == "started") ++starts;
    if (e["event"] == "end") ++ends;
    if (e["event"] == "stats") {
      statsHosts.insert(e["host"].get<std::string>());
      for (const auto& m : e["modules"]) iterations[m["id"]] = m["iterations"].get<uint64_t>();
      links = links || !e["links"].empty();
    }
    if (e["event"] == "module_exit") {
      EXPECT_EQ(e["exit"], "status 0") << e;
      EXPECT_EQ(e["host"], hostOf[e["module"]]) << e;
      exited.insert(e["module"].get<std::string>());
    }
  }
  EXPECT_EQ(starts, 1);
  EXPECT_EQ(ends, 1);
  EXPECT_EQ(statsHosts.size(), 3u);
  EXPECT_TRUE(links) << "no stats event carried the links between hosts";
  EXPECT_EQ(exited.size(), hostOf.size());
  for (const auto& [module, host] : hostOf) EXPECT_EQ(iterations[module], 200u) << module;
  EXPECT_EQ(lines.back()["event"], "end");
  EXPECT_EQ(lines.back()["exit_code"], 0);
  EXPECT_EQ(lines.back()["status"], "ok");
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(LaunchEvents, MonitorShowsEveryHostAndModuleOfAStreamAndHowItEnded) {
  TempDir dir;
  const auto events = dir.file("events.jsonl");
  const auto launched = launchThreeHosts(dir, 50, events);
  ASSERT_EQ(launched.exitCode, 0) << launched.err;
  const auto shown = runCommand({binDir() + "/vrflow", "monitor", "--events", events, "--once"});
  ASSERT_EQ(shown.exitCode, 0) << shown.err;
  for (const char* module : {"chain", "springs", "gravity", "relay", "recorder"}) {
    EXPECT_NE(shown.out.find(module), std::string::npos) << module << "\n" << shown.out;
  }
  EXPECT_NE(shown.out.find("LINKS"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("run ended: ok (exit 0)"), std::string::npos) << shown.out;

  const auto missing =
      runCommand({binDir() + "/vrflow", "monitor", "--events", dir.file("none.jsonl"), "--once"});
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("cannot read the events"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace vrflow::testing
