// A launch's report and progress (issue 19, items 6 and 7): the merged report is valid against
// the report's JSON Schema and carries the version; the launch ends with one summary line.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>

#include "formats_support.hpp"
#include "process_helpers.hpp"
#include "vrflow/base/version.hpp"

namespace vrflow::testing {
namespace {

TEST(LaunchFormats, AThreeHostLaunchsReportIsValidAndItEndsWithOneSummaryLine) {
  TempDir dir;
  const std::string file = sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
  const auto result = runVrflow({"launch", file, "--backend", "local", "-n", "30", "--report",
                                 dir.file("r.json"), "--trace", dir.file("t.json")},
                                120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto report = checkedReport(dir.file("r.json"));
  EXPECT_EQ(report["vrflow_version"], versionText());
  EXPECT_EQ(report["exit_code"], 0);
  EXPECT_EQ(report["timing"]["hosts"], 3);
  ASSERT_EQ(report["modules"].size(), 5u);
  for (const auto& m : report["modules"]) EXPECT_EQ(m["exit_code"], 0) << m;
  const auto trace = nlohmann::json::parse(readFile(dir.file("t.json")));
  EXPECT_EQ(trace["otherData"]["vrflow_version"], versionText());
  // Not on a terminal: no live line, one summary line.
  EXPECT_EQ(result.err.find('\r'), std::string::npos) << result.err;
  const std::regex summary(
      "vrflow: 30 of 30 iterations in [0-9]+\\.[0-9] s \\([0-9]+\\.[0-9] it/s\\), status ok\n");
  EXPECT_TRUE(std::regex_search(result.err, summary)) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(LaunchFormats, AFailedLaunchsReportIsValidAndNamesTheStatus) {
  TempDir dir;
  const std::string file = sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
  // Stopped by --timeout long before -n: every host's share still makes the report.
  const auto result = runVrflow({"launch", file, "--backend", "local", "-n", "100000", "--timeout",
                                 "2", "--report", dir.file("r.json")},
                                120);
  ASSERT_EQ(result.exitCode, 3) << result.err;
  const auto report = checkedReport(dir.file("r.json"));
  EXPECT_EQ(report["exit_code"], 3);
  EXPECT_EQ(report["status"], "timeout");
  EXPECT_NE(result.err.find("iterations in "), std::string::npos) << result.err;
  EXPECT_NE(result.err.find(", status timeout\n"), std::string::npos) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

// A copy of `vrflow` whose vrflow-daemon is told that the launcher is vrflow 0.0.1: how a host
// with another vrflow installed looks to a launch.
TEST(LaunchFormats, ADaemonOfAnotherVersionStopsTheLaunchNamingItsHost) {
  TempDir dir;
  std::filesystem::create_directory(dir.file("bin"));
  std::filesystem::copy_file(binDir() + "/vrflow", dir.file("bin/vrflow"));
  std::filesystem::permissions(dir.file("bin/vrflow"), std::filesystem::perms::owner_all);
  // The copy finds the libraries and packages as an installed tree would (bin/../lib, share/).
  std::filesystem::create_directory_symlink(binDir() + "/../lib", dir.file("lib"));
  std::filesystem::create_directory_symlink(binDir() + "/../share", dir.file("share"));
  dir.write("bin/vrflow-daemon",
            "#!/bin/sh\n"
            "for a in \"$@\"; do\n"
            "  shift\n"
            "  if [ \"$previous\" = --launcher-version ]; then a=0.0.1; fi\n"
            "  set -- \"$@\" \"$a\"\n"
            "  previous=$a\n"
            "done\n"
            "exec " +
                binDir() + "/vrflow-daemon \"$@\"\n");
  std::filesystem::permissions(dir.file("bin/vrflow-daemon"), std::filesystem::perms::owner_all);
  const std::string file = sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
  const auto result =
      runCommand({dir.file("bin/vrflow"), "launch", file, "--backend", "local", "-n", "30"}, 120);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  const std::regex named(
      "vrflow: host '[abc]': vrflow-daemon here is vrflow " +
      std::regex_replace(std::string(versionText()), std::regex(R"([.()+])"), R"(\$&)") +
      ", the launcher is vrflow 0\\.0\\.1: install the same vrflow on every host; "
      "stopping every host\n");
  EXPECT_TRUE(std::regex_search(result.err, named)) << result.err;
  EXPECT_EQ(result.err.find("iterations in"), result.err.rfind("iterations in")) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
