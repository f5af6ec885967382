// End-to-end tests of the logs of `vrflow run` (docs/logs.md): real module processes whose
// stdout and stderr are captured, prefixed on the terminal and written to their log files.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// A chatter module (testing/chatter, with `params` as param elements) feeding a recorder.
std::string chatterApp(const std::string& params, const std::string& csv) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"logs\" version=\"1\">\n"
         "  <hosts><host id=\"h1\" address=\"127.0.0.1\"/></hosts>\n  <modules>\n"
         "    <module id=\"talk\" package=\"testing\" type=\"chatter\" host=\"h1\">\n" +
         params +
         "    </module>\n"
         "    <module id=\"rec\" package=\"core\" type=\"recorder\" host=\"h1\">\n"
         "      <param name=\"file\" value=\"" +
         csv +
         "\"/>\n    </module>\n  </modules>\n"
         "  <connections><connection from=\"talk.out\" to=\"rec.in\"/></connections>\n"
         "</application>\n";
}

std::string param(const std::string& name, const std::string& value) {
  return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class LogsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The default log folder is under XDG_STATE_HOME: this test's, never the user's.
    setenv("XDG_STATE_HOME", dir.file("state").c_str(), 1);
  }
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

TEST_F(LogsTest, ModuleLinesArePrefixedOnStderrAndWrittenToTheModulesLogFile) {
  const std::string logs = dir.file("logs");
  const std::string file = dir.write(
      "app.xml",
      chatterApp(param("lines", "3") + param("partial", "last words"), dir.file("out.csv")));
  const auto result = runVrflow({"run", file, "-n", "20", "--log-dir", logs});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  for (const char* line : {"out 1", "err 1", "out 3", "err 3", "last words"}) {
    EXPECT_TRUE(contains(result.err, "[talk@h1] " + std::string(line) + "\n")) << result.err;
  }
  EXPECT_FALSE(contains(result.err, "\033[")) << "colour when stderr is not a terminal";
  // Each line as the module wrote it, stdout and stderr in the order written; the last one,
  // without its newline, too.
  EXPECT_EQ(readLines(logs + "/talk.log"),
            (std::vector<std::string>{"out 1", "err 1", "out 2", "err 2", "out 3", "err 3",
                                      "last words"}));
  EXPECT_TRUE(std::filesystem::exists(logs + "/rec.log"));
  EXPECT_TRUE(contains(result.err, "info vrflow: run logs-")) << result.err;
  EXPECT_TRUE(contains(result.err, ", logs in " + logs + "\n")) << result.err;
  const std::string runtime = readFile(logs + "/vrflow.log");
  EXPECT_TRUE(contains(runtime, " info [")) << runtime;
  EXPECT_TRUE(contains(runtime, "vrflow: run logs-")) << runtime;
  EXPECT_FALSE(contains(runtime, "out 1")) << "module lines are not the runtime's";
}

TEST_F(LogsTest, WithoutLogDirTheRunGetsAFolderOfItsOwnUnderTheStateFolder) {
  const std::string file = dir.write("app.xml", chatterApp(param("lines", "1"), dir.file("o.csv")));
  const auto result = runVrflow({"run", file, "-n", "5"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const std::string root = dir.file("state") + "/vrflow/logs";
  ASSERT_TRUE(contains(result.err, ", logs in " + root + "/logs-")) << result.err;
  std::vector<std::filesystem::path> runs;
  for (const auto& entry : std::filesystem::directory_iterator(root)) runs.push_back(entry.path());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(std::filesystem::status(runs[0]).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_all);
  EXPECT_EQ(readLines(runs[0].string() + "/talk.log"),
            (std::vector<std::string>{"out 1", "err 1"}));
}

TEST_F(LogsTest, CrashedModulesFailureNamesItsLogFileAndShowsItsLastLines) {
  const std::string logs = dir.file("logs");
  const std::string report = dir.file("report.json");
  const std::string file = dir.write(
      "app.xml", chatterApp(param("lines", "12") + param("crash", "3"), dir.file("out.csv")));
  const auto result = runVrflow({"run", file, "-n", "50", "--log-dir", logs, "--report", report});
  ASSERT_EQ(result.exitCode, 1) << result.err;
  EXPECT_TRUE(contains(result.err, "was killed by signal 11")) << result.err;
  EXPECT_TRUE(contains(result.err, "vrflow: the last 10 lines of module 'talk' (its log: " + logs +
                                       "/talk.log):\n"
                                       "  err 8\n  out 9\n  err 9\n  out 10\n  err 10\n"
                                       "  out 11\n  err 11\n  out 12\n  err 12\n"
                                       "  about to crash\n"))
      << result.err;
  // Nothing it printed before it crashed is lost.
  const auto lines = readLines(logs + "/talk.log");
  ASSERT_EQ(lines.size(), 25u);
  EXPECT_EQ(lines.front(), "out 1");
  EXPECT_EQ(lines.back(), "about to crash");
  // The report's error stays one line, without the log.
  const auto json = nlohmann::json::parse(readFile(report));
  EXPECT_FALSE(contains(json["error"].get<std::string>(), "its log")) << json["error"];
}

TEST_F(LogsTest, ModulesInheritNoDescriptorButTheirSegment) {
  // A descriptor without close-on-exec, inherited by vrflow from whoever started it.
  const int stray = open("/dev/null", O_RDONLY);
  ASSERT_GE(stray, 0);
  const std::string file = dir.write(
      "app.xml", chatterApp(param("lines", "0") + param("fds", "1"), dir.file("out.csv")));
  const auto result = runVrflow({"run", file, "-n", "5", "--log-dir", dir.file("logs")});
  close(stray);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto lines = readLines(dir.file("logs/talk.log"));
  ASSERT_EQ(lines.size(), 1u) << result.err;
  EXPECT_TRUE(contains(lines[0], "vrflow-segment")) << lines[0];
}

TEST_F(LogsTest, FloodingModuleDoesNotGrowVrflowsMemory) {
  constexpr int kMiB = 200;
  const std::string logs = dir.file("logs");
  const std::string file = dir.write(
      "app.xml",
      chatterApp(param("lines", "0") + param("flood", std::to_string(kMiB)), dir.file("out.csv")));
  // The terminal's copy goes to /dev/null: this test keeps none of it.
  const std::string command = binDir() + "/vrflow --packages " + binDir() +
                              "/../test-packages run " + file + " -n 5 --log-dir " + logs +
                              " 2>/dev/null";
  const auto result = runCommand({"/bin/sh", "-c", command}, 300);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_GE(std::filesystem::file_size(logs + "/talk.log"), uint64_t{kMiB} * 1024 * 1024 - 100);
  const std::string log = readFile(logs + "/talk.log");
  EXPECT_EQ(log.substr(log.size() - 11), "flood done\n");
  // The largest process this test waited for (vrflow, sh, the module) stayed far below what
  // went through it.
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  // (Not under a sanitizer: its allocator's quarantine and shadow memory dwarf the bound.)
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  EXPECT_LT(usage.ru_maxrss, kMiB * 1024 / 2) << "KiB";
#endif
}

TEST_F(LogsTest, LogLevelChoosesWhichRuntimeLinesAreShownAndLogged) {
  const std::string file = dir.write(
      "app.xml", chatterApp(param("lines", "1") + param("crash", "2"), dir.file("out.csv")));
  const auto warn =
      runVrflow({"run", file, "-n", "5", "--log-dir", dir.file("warn"), "--log-level", "warn"});
  EXPECT_EQ(warn.exitCode, 1);
  EXPECT_FALSE(contains(warn.err, "vrflow: run ")) << warn.err;
  EXPECT_TRUE(contains(warn.err, "error vrflow: module 'talk'")) << warn.err;
  EXPECT_TRUE(contains(warn.err, "[talk@h1] out 1")) << "module lines are not filtered";
  EXPECT_FALSE(contains(readFile(dir.file("warn/vrflow.log")), "vrflow: run "));
  const auto off =
      runVrflow({"run", file, "-n", "5", "--log-dir", dir.file("off"), "--log-level", "off"});
  EXPECT_EQ(off.exitCode, 1);
  EXPECT_FALSE(contains(off.err, "vrflow: module 'talk'")) << off.err;
  EXPECT_EQ(readFile(dir.file("off/vrflow.log")), "");
  const auto bad = runVrflow({"run", file, "--log-level", "loud"});
  EXPECT_EQ(bad.exitCode, 2);
  EXPECT_TRUE(contains(bad.err, "--log-level")) << bad.err;
}

TEST_F(LogsTest, UnusableLogDirIsRefusedBeforeAnythingStarts) {
  const std::string csv = dir.file("out.csv");
  const std::string file = dir.write("app.xml", chatterApp(param("lines", "1"), csv));
  const std::string notAFolder = dir.write("plain", "x");
  const auto result = runVrflow({"run", file, "-n", "5", "--log-dir", notAFolder});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_EQ(result.err,
            "vrflow: cannot use the log folder '" + notAFolder + "': it is not a folder\n");
  const auto under = runVrflow({"run", file, "-n", "5", "--log-dir", notAFolder + "/logs"});
  EXPECT_EQ(under.exitCode, 2);
  EXPECT_TRUE(contains(under.err, "vrflow: cannot use the log folder '" + notAFolder + "/logs'"))
      << under.err;
  EXPECT_FALSE(std::filesystem::exists(csv)) << "the run started";
  // A missing folder is made, with its parents.
  const auto made = runVrflow({"run", file, "-n", "5", "--log-dir", dir.file("a/b/logs")});
  EXPECT_EQ(made.exitCode, 0) << made.err;
  EXPECT_EQ(readLines(dir.file("a/b/logs/talk.log")), (std::vector<std::string>{"out 1", "err 1"}));
}

}  // namespace
}  // namespace vrflow::testing
