// Versions and formats (issue 19, item 6): `--version` of every program, the version in the
// report and the trace, the report's JSON Schema and its exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "formats_support.hpp"
#include "process_helpers.hpp"
#include "vrflow/base/version.hpp"

namespace vrflow::testing {
namespace {

// What `PROGRAM --version` must print.
std::string versionLineOf(const std::string& program) {
  return program + ": vrflow " + std::string(versionText()) + "\n";
}

TEST(Versions, VersionTextStartsWithTheProjectVersion) {
  EXPECT_EQ(std::string(versionText()).rfind(std::string(kVersion), 0), 0u) << versionText();
  EXPECT_EQ(versionLine("/usr/bin/vrflow-daemon"),
            "vrflow-daemon: vrflow " + std::string(versionText()));
}

TEST(Versions, EveryProgramAndEveryModuleOfTheInstalledPackagesAnswersVersion) {
  std::vector<std::string> programs{binDir() + "/vrflow", binDir() + "/vrflow-daemon"};
  if (std::ifstream(binDir() + "/vrflow-editor").good()) {
    programs.push_back(binDir() + "/vrflow-editor");  // before any display is opened
  }
  // Every module executable the catalog knows: core, the node packages, the test packages.
  const auto types = runVrflow({"types", "--json"});
  ASSERT_EQ(types.exitCode, 0) << types.err;
  std::set<std::string> executables;
  const auto listed = nlohmann::json::parse(types.out);  // alive through the loop
  for (const auto& m : listed["modules"]) {
    // Those built here (a test package may name a system program such as /bin/true).
    const auto executable = m["executable"].get<std::string>();
    if (executable.rfind(binDir() + "/", 0) == 0) executables.insert(executable);
  }
  ASSERT_GE(executables.size(), 6u) << types.out;
  programs.insert(programs.end(), executables.begin(), executables.end());
  for (const auto& program : programs) {
    if (!std::ifstream(program).good()) continue;  // a package whose executable is not built
    const auto result = runCommand({program, "--version"}, 30);
    const std::string name = program.substr(program.rfind('/') + 1);
    EXPECT_EQ(result.exitCode, 0) << program << ": " << result.err;
    EXPECT_EQ(result.out, versionLineOf(name)) << program;
  }
}

TEST(Versions, ADaemonRefusesALauncherOfAnotherVersionAndNamesItsHost) {
  TempDir dir;
  const std::string file = relayPipeline(dir);
  const auto result =
      runCommand({binDir() + "/vrflow-daemon", file, "--host", "h1", "--control", "--packages",
                  binDir() + "/../test-packages", "--launcher-version", "0.0.1"});
  EXPECT_EQ(result.exitCode, 2) << result.err;
  // One "error" line on the control channel, which the launcher prints as "host 'h1': ...".
  EXPECT_EQ(result.out, "error vrflow-daemon here is vrflow " + std::string(versionText()) +
                            ", the launcher is vrflow 0.0.1: install the same vrflow on every "
                            "host\n");
  EXPECT_NE(result.err.find("vrflow-daemon (host h1): "), std::string::npos) << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(ReportSchema, ThePlainRunsReportIsValidAndCarriesTheVersionAndExitCodes) {
  TempDir dir;
  const auto run = runVrflow({"run", relayPipeline(dir), "-n", "20", "--report", dir.file("r.json"),
                              "--trace", dir.file("t.json")});
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const auto report = checkedReport(dir.file("r.json"));
  EXPECT_EQ(report["vrflow_version"], versionText());
  EXPECT_EQ(report["exit_code"], 0);
  EXPECT_EQ(report["status"], "ok");
  for (const auto& m : report["modules"]) {
    EXPECT_EQ(m["exit_code"], 0) << m;
    EXPECT_TRUE(m["signal"].is_null()) << m;
    EXPECT_EQ(m["exit"], "status 0") << m;
  }
  const auto trace = nlohmann::json::parse(readFile(dir.file("t.json")));
  EXPECT_EQ(trace["otherData"]["vrflow_version"], versionText());
}

TEST(ReportSchema, AFailedRunsReportIsValidWithTheModulesExitStatusAndSignal) {
  TempDir dir;
  const std::string killed =
      relayPipeline(dir, "testing/crash", paramXml("at", "3") + paramXml("signal", "9"));
  const auto run = runVrflow({"run", killed, "-n", "50", "--report", dir.file("r.json")});
  ASSERT_EQ(run.exitCode, 1) << run.err;
  const auto report = checkedReport(dir.file("r.json"));
  EXPECT_EQ(report["exit_code"], 1);
  EXPECT_EQ(report["status"], "failed");
  EXPECT_EQ(report["modules"][1]["id"], "relay");
  EXPECT_EQ(report["modules"][1]["signal"], 9) << report["modules"][1];
  EXPECT_TRUE(report["modules"][1]["exit_code"].is_null()) << report["modules"][1];
  EXPECT_EQ(report["modules"][1]["exit"], "signal 9");

  const std::string exits =
      relayPipeline(dir, "testing/crash", paramXml("at", "3") + paramXml("status", "7"));
  const auto second = runVrflow({"run", exits, "-n", "50", "--report", dir.file("s.json")});
  ASSERT_EQ(second.exitCode, 1) << second.err;
  const auto failed = checkedReport(dir.file("s.json"));
  EXPECT_EQ(failed["modules"][1]["exit_code"], 7) << failed["modules"][1];
  EXPECT_TRUE(failed["modules"][1]["signal"].is_null());
  EXPECT_TRUE(leftoverProcesses().empty());
}

TEST(ReportSchema, TheSchemaRejectsBrokenReports) {
  TempDir dir;
  ASSERT_EQ(
      runVrflow({"run", relayPipeline(dir), "-n", "5", "--report", dir.file("r.json")}).exitCode,
      0);
  const auto good = nlohmann::json::parse(readFile(dir.file("r.json")));
  const std::vector<std::pair<std::string, nlohmann::json>> broken = [&] {
    std::vector<std::pair<std::string, nlohmann::json>> list;
    auto r = good;
    r.erase("modules");
    list.push_back({"'modules' is a required property", r});
    r = good;
    r["exit_code"] = "0";
    list.push_back({"'0' is not of type 'integer'", r});
    r = good;
    r["status"] = "fine";
    list.push_back({"'fine' is not one of", r});
    r = good;
    r["modules"][0]["iterations"] = -1;
    list.push_back({"-1 is less than the minimum of 0", r});
    r = good;
    r["outputs"][0]["last_digest"] = "xyz";
    list.push_back({"'xyz' does not match", r});
    r = good;
    r["format"] = "vrflow-run-report/2";
    list.push_back({"'vrflow-run-report/1' was expected", r});
    return list;
  }();
  for (std::size_t i = 0; i < broken.size(); ++i) {
    const std::string path =
        dir.write("broken" + std::to_string(i) + ".json", broken[i].second.dump());
    const auto result = validateReport(path);
    EXPECT_EQ(result.exitCode, 1) << broken[i].first;
    EXPECT_NE(result.out.find(broken[i].first), std::string::npos) << result.out;
  }
}

}  // namespace
}  // namespace vrflow::testing
