// `vrflow run --events`: the machine-readable event stream of a run (docs/events.md).
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::vector<nlohmann::json> parseEvents(const std::string& text) {
  std::vector<nlohmann::json> events;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    auto event = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    EXPECT_TRUE(event.is_object() && event.contains("event") && event.contains("time")) << line;
    if (event.is_object()) events.push_back(std::move(event));
  }
  return events;
}

std::vector<nlohmann::json> ofKind(const std::vector<nlohmann::json>& events,
                                   const std::string& kind) {
  std::vector<nlohmann::json> found;
  for (const auto& e : events) {
    if (e["event"] == kind) found.push_back(e);
  }
  return found;
}

TEST(EventStream, ARunSaysStartedThenStatsAndModuleExitsThenEnd) {
  TempDir dir;
  const auto result =
      runCommand({"/bin/sh", "-c",
                  "cd " + dir.path() + " && " + binDir() + "/vrflow run " + sourceDir() +
                      "/examples/pipeline/pipeline.xml -n 200 --events -"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto events = parseEvents(result.out);
  ASSERT_GE(events.size(), 3u) << result.out;
  EXPECT_EQ(events.front()["event"], "started");
  EXPECT_EQ(events.front()["application"], "pipeline");
  const std::set<std::string> modules{"chain", "springs", "gravity", "relay", "recorder"};
  std::set<std::string> started;
  for (const auto& m : events.front()["modules"]) started.insert(m["id"].get<std::string>());
  EXPECT_EQ(started, modules);

  const auto stats = ofKind(events, "stats");
  ASSERT_FALSE(stats.empty()) << result.out;
  std::map<std::string, uint64_t> iterations;  // the last count of each module
  for (const auto& s : stats) {
    for (const auto& m : s["modules"]) iterations[m["id"]] = m["iterations"].get<uint64_t>();
    EXPECT_TRUE(s["connections"].is_array());
  }
  for (const auto& id : modules) EXPECT_EQ(iterations[id], 200u) << id;

  std::set<std::string> exited;
  for (const auto& e : ofKind(events, "module_exit")) {
    EXPECT_EQ(e["exit"], "status 0") << e.dump();
    EXPECT_EQ(e["host"], "local");
    exited.insert(e["module"].get<std::string>());
  }
  EXPECT_EQ(exited, modules);

  const auto& end = events.back();
  EXPECT_EQ(end["event"], "end");
  EXPECT_EQ(end["exit_code"], 0);
  EXPECT_EQ(end["status"], "ok");
  EXPECT_EQ(ofKind(events, "end").size(), 1u);
  double previous = 0;
  for (const auto& e : events) {
    EXPECT_GE(e["time"].get<double>(), previous) << e.dump();
    previous = e["time"].get<double>();
  }
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(EventStream, AFailedRunEndsTheStreamWithItsExitStatusAndTheModulesOwn) {
  TempDir dir;
  const auto file = dir.write("crash.xml", R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="crash" version="1">
  <modules>
    <module id="src" package="core" type="source"/>
    <module id="bad" package="testing" type="crash">
      <param name="at" value="5"/>
      <param name="status" value="7"/>
    </module>
  </modules>
  <connections>
    <connection from="src.out" to="bad.in"/>
  </connections>
</application>
)");
  const auto events = dir.file("events.jsonl");
  const auto result = runVrflow({"run", file, "-n", "100", "--events", events});
  ASSERT_EQ(result.exitCode, 1) << result.err;
  const auto parsed = parseEvents(readFile(events));
  ASSERT_FALSE(parsed.empty());
  EXPECT_EQ(parsed.front()["event"], "started");
  const auto& end = parsed.back();
  EXPECT_EQ(end["event"], "end");
  EXPECT_EQ(end["exit_code"], 1);
  EXPECT_EQ(end["status"], "failed");
  EXPECT_NE(end["error"].get<std::string>().find("module 'bad'"), std::string::npos) << end;
  bool badExit = false;
  for (const auto& e : ofKind(parsed, "module_exit")) {
    if (e["module"] == "bad") badExit = e["exit"] == "status 7";
  }
  EXPECT_TRUE(badExit) << readFile(events);
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(EventStream, AnApplicationThatCannotRunStillEndsTheStream) {
  TempDir dir;
  const auto file = dir.write("broken.xml", "<application name=\"x\" version=\"1\"><modules>");
  const auto result = runVrflow({"run", file, "--events", "-"});
  EXPECT_EQ(result.exitCode, 2);
  const auto events = parseEvents(result.out);
  ASSERT_EQ(events.size(), 1u) << result.out;
  EXPECT_EQ(events[0]["event"], "end");
  EXPECT_EQ(events[0]["exit_code"], 2);
  EXPECT_EQ(events[0]["status"], "invalid");
  EXPECT_NE(events[0]["error"].get<std::string>().find("broken.xml"), std::string::npos)
      << events[0];
}

TEST(EventStream, AnEventsFileThatCannotBeWrittenIsRefusedBeforeTheRun) {
  const auto result = runVrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n", "1",
                                 "--events", "/nonexistent-folder/events.jsonl"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("cannot write the events to '/nonexistent-folder/events.jsonl'"),
            std::string::npos)
      << result.err;
}

TEST(EventStream, AReportThatCannotBeWrittenEndsTheStreamSayingSo) {
  const auto result = runVrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n", "1",
                                 "--report", "/nonexistent-folder/r.json", "--events", "-"});
  EXPECT_EQ(result.exitCode, 2);
  const auto events = parseEvents(result.out);
  ASSERT_EQ(events.size(), 1u) << result.out;
  EXPECT_EQ(events[0]["event"], "end");
  EXPECT_EQ(events[0]["status"], "invalid");
  EXPECT_NE(events[0]["error"].get<std::string>().find(
                "cannot write the report to '/nonexistent-folder/r.json'"),
            std::string::npos)
      << events[0];
}

}  // namespace
}  // namespace vrflow::testing
