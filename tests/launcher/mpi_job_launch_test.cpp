// An MPI job made of several modules under `vrflow launch`: the daemon of the job's host, not
// the first one, starts its one mpirun; the job's modules talk to modules on another host.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// The point each mpitest/rank module put per iteration, as its core/recorder wrote it:
// source module, then x, y, z = MPI rank, MPI size, sum of the ranks.
std::vector<std::string> recordedPoints(const std::string& path) {
  std::vector<std::string> rows;
  for (const auto& cells : readCsvRows(path)) {
    if (cells.size() < 9 || cells[4] != "object") continue;
    rows.push_back(cells[1] + " " + cells[6] + " " + cells[7] + " " + cells[8]);
  }
  return rows;
}

TEST(LaunchMpiJob, AJobOnANonFirstHostIsStartedByThatHostsDaemon) {
  if (runCommand({"/bin/sh", "-c", "command -v mpirun"}, 10).exitCode != 0) {
    GTEST_SKIP() << "mpirun is not installed";
  }
  TempDir dir;
  // VRFLOW_MPIRUN: a wrapper that logs its arguments and runs the real mpirun.
  const auto wrapper = dir.write(
      "mpirun", "#!/bin/sh\necho \"$@\" >> '" + dir.file("mpirun.log") + "'\nexec mpirun \"$@\"\n");
  ASSERT_EQ(chmod(wrapper.c_str(), 0755), 0);
  // Job `water` (b0, b1) on host c; their recorders on host a, across the links.
  std::string modules, connections;
  for (const std::string id : {"b0", "b1"}) {
    modules += "    <module id=\"" + id + "\" package=\"mpitest\" type=\"rank\" host=\"c\">\n" +
               "      <param name=\"job\" value=\"water\"/>\n    </module>\n";
    modules += "    <module id=\"rec-" + id +
               "\" package=\"core\" type=\"recorder\" host=\"a\">\n" +
               "      <param name=\"file\" value=\"" + dir.file(id + ".csv") + "\"/>\n" +
               "    </module>\n";
    connections += "    <connection from=\"" + id + ".out\" to=\"rec-" + id + ".in\"/>\n";
  }
  const std::string hosts =
      "  <hosts>\n    <host id=\"a\" address=\"127.0.0.1\"/>\n"
      "    <host id=\"b\" address=\"127.0.0.2\"/>\n"
      "    <host id=\"c\" address=\"127.0.0.3\"/>\n  </hosts>\n";
  const auto file =
      dir.write("launch.xml",
                "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                "<application name=\"job-on-c\" version=\"1\">\n" +
                    hosts + "  <modules>\n" + modules + "  </modules>\n  <connections>\n" +
                    connections + "  </connections>\n</application>\n");
  setenv("VRFLOW_MPIRUN", wrapper.c_str(), 1);
  const auto result = runVrflow(
      {"launch", file, "--backend", "local", "-n", "5", "--report", dir.file("report.json")}, 120);
  unsetenv("VRFLOW_MPIRUN");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(recordedPoints(dir.file("b0.csv")), std::vector<std::string>(5, "b0 0 2 1"));
  EXPECT_EQ(recordedPoints(dir.file("b1.csv")), std::vector<std::string>(5, "b1 1 2 1"));
  const auto calls = readLines(dir.file("mpirun.log"));
  ASSERT_EQ(calls.size(), 1u) << "one mpirun, by host c's daemon";
  EXPECT_NE(calls[0].find("-np 2"), std::string::npos) << calls[0];
  const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
  EXPECT_EQ(report["status"], "ok");
  ASSERT_EQ(report["modules"].size(), 4u);
  for (const auto& module : report["modules"]) {
    const std::string id = module["id"];
    EXPECT_EQ(module["host"], id.rfind("rec-", 0) == 0 ? "a" : "c") << id;
    EXPECT_EQ(module["exit"], "status 0") << id;
  }
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << left.front();
}

}  // namespace
}  // namespace vrflow::testing
