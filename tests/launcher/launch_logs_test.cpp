// End-to-end tests of a launch's logs (docs/logs.md): every host's module lines reach the
// launcher's machine, prefixed on its stderr and written to its log folder.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// Chatter modules on hosts a and b, their recorders on host c.
std::string threeHostsApp(const std::string& aParams, const std::string& dir) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"chat3\" version=\"1\">\n"
         "  <hosts><host id=\"a\" address=\"127.0.0.1\"/><host id=\"b\" address=\"127.0.0.2\"/>"
         "<host id=\"c\" address=\"127.0.0.3\"/></hosts>\n  <modules>\n"
         "    <module id=\"ta\" package=\"testing\" type=\"chatter\" host=\"a\">" +
         aParams +
         "</module>\n"
         "    <module id=\"tb\" package=\"testing\" type=\"chatter\" host=\"b\">"
         "<param name=\"lines\" value=\"3\"/></module>\n"
         "    <module id=\"ra\" package=\"core\" type=\"recorder\" host=\"c\">"
         "<param name=\"file\" value=\"" +
         dir +
         "/a.csv\"/></module>\n"
         "    <module id=\"rb\" package=\"core\" type=\"recorder\" host=\"c\">"
         "<param name=\"file\" value=\"" +
         dir +
         "/b.csv\"/></module>\n  </modules>\n"
         "  <connections><connection from=\"ta.out\" to=\"ra.in\"/>"
         "<connection from=\"tb.out\" to=\"rb.in\"/></connections>\n</application>\n";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class LaunchLogsTest : public ::testing::Test {
 protected:
  void SetUp() override { setenv("XDG_STATE_HOME", dir.file("state").c_str(), 1); }
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

TEST_F(LaunchLogsTest, EveryHostsModuleLinesArriveInTheLaunchersLogFolder) {
  const std::string logs = dir.file("logs");
  const std::string file =
      dir.write("app.xml", threeHostsApp("<param name=\"lines\" value=\"2\"/>"
                                         "<param name=\"partial\" value=\"end of a\"/>",
                                         dir.path()));
  const auto result = runVrflow({"launch", file, "-n", "20", "--log-dir", logs}, 120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readLines(logs + "/ta.log"),
            (std::vector<std::string>{"out 1", "err 1", "out 2", "err 2", "end of a"}));
  EXPECT_EQ(readLines(logs + "/tb.log"),
            (std::vector<std::string>{"out 1", "err 1", "out 2", "err 2", "out 3", "err 3"}));
  EXPECT_EQ(readFile(logs + "/ra.log"), "") << "every module has its log, even a silent one";
  for (const char* line : {"[ta@a] out 1\n", "[ta@a] end of a\n", "[tb@b] err 3\n"}) {
    EXPECT_TRUE(contains(result.err, line)) << line << " in:\n" << result.err;
  }
  EXPECT_TRUE(contains(result.err, "vrflow: run chat3-")) << result.err;
  EXPECT_TRUE(contains(readFile(logs + "/vrflow.log"), ", logs in " + logs));
}

TEST_F(LaunchLogsTest, AModuleThatCrashesOnAnotherHostShowsItsLastLinesOnTheLaunchersTerminal) {
  const std::string logs = dir.file("logs");
  const std::string file = dir.write("app.xml", threeHostsApp("<param name=\"lines\" value=\"2\"/>"
                                                              "<param name=\"crash\" value=\"3\"/>",
                                                              dir.path()));
  const auto result = runVrflow({"launch", file, "-n", "50", "--log-dir", logs}, 120);
  ASSERT_EQ(result.exitCode, 1) << result.err;
  EXPECT_TRUE(contains(result.err, "was killed by signal 11")) << result.err;
  EXPECT_TRUE(contains(result.err,
                       "vrflow: the last 5 lines of module 'ta':\n  out 1\n  err 1\n"
                       "  out 2\n  err 2\n  about to crash\n"))
      << result.err;
  EXPECT_EQ(readLines(logs + "/ta.log"),
            (std::vector<std::string>{"out 1", "err 1", "out 2", "err 2", "about to crash"}));
}

TEST_F(LaunchLogsTest, AFloodingModulesLinesOverTheForwardingRateAreCountedAsDropped) {
  const std::string logs = dir.file("logs");
  const std::string file =
      dir.write("app.xml", threeHostsApp("<param name=\"lines\" value=\"0\"/>"
                                         "<param name=\"flood\" value=\"10\"/>",
                                         dir.path()));
  const auto result = runVrflow({"launch", file, "-n", "5", "--log-dir", logs}, 180);
  ASSERT_EQ(result.exitCode, 0) << result.err.substr(result.err.size() - 2000);
  // Each line either arrived or was counted in a note: none is lost without a word.
  constexpr uint64_t kLines = 10 * 1024 * 1024 / 100 + 1;  // 100-byte lines, then "flood done"
  uint64_t arrived = 0, dropped = 0;
  for (const auto& line : readLines(logs + "/ta.log")) {
    const std::string prefix = "vrflow: ";
    if (line.rfind(prefix, 0) == 0) {
      ASSERT_TRUE(contains(line, " lines dropped")) << line;
      dropped += std::stoull(line.substr(prefix.size()));
    } else {
      ++arrived;
    }
  }
  EXPECT_GT(dropped, 0u);
  EXPECT_EQ(arrived + dropped, kLines);
}

TEST_F(LaunchLogsTest, ADaemonGivenALogDirKeepsItsHostsOwnCopy) {
  const std::string logs = dir.file("host-logs");
  const std::string file = dir.write(
      "app.xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"one\" version=\"1\">\n"
      "  <hosts><host id=\"a\" address=\"127.0.0.1\"/></hosts>\n  <modules>\n"
      "    <module id=\"ta\" package=\"testing\" type=\"chatter\" host=\"a\">"
      "<param name=\"lines\" value=\"2\"/></module>\n"
      "    <module id=\"ra\" package=\"core\" type=\"recorder\" host=\"a\">"
      "<param name=\"file\" value=\"" +
          dir.file("a.csv") +
          "\"/></module>\n  </modules>\n"
          "  <connections><connection from=\"ta.out\" to=\"ra.in\"/></connections>\n"
          "</application>\n");
  const auto result = runCommand({binDir() + "/vrflow-daemon", file, "--host", "a", "--packages",
                                  binDir() + "/../test-packages", "-n", "5", "--log-dir", logs,
                                  "--log-level", "debug"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readLines(logs + "/ta.log"),
            (std::vector<std::string>{"out 1", "err 1", "out 2", "err 2"}));
  EXPECT_TRUE(contains(result.err, "[ta@a] err 2\n")) << result.err;
  EXPECT_TRUE(std::filesystem::exists(logs + "/vrflow.log"));
  const auto refused = runCommand({binDir() + "/vrflow-daemon", file, "--host", "a", "--packages",
                                   binDir() + "/../test-packages", "--log-dir", file});
  EXPECT_EQ(refused.exitCode, 2);
  EXPECT_TRUE(contains(refused.err, "cannot use the log folder '" + file + "'")) << refused.err;
}

}  // namespace
}  // namespace vrflow::testing
