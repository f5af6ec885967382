// End-to-end tests of MPI jobs made of several modules (manifest attribute mpi-job) through the
// `vrflow` command: one mpirun per job, each rank joining as its own module, grouping by the
// job parameter's value, validation, and failures. The test package `mpitest` (tests/modules)
// has the module type `rank`; each module here feeds a core/recorder of its own.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "process_helpers.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::testing {
namespace {

std::string application(const std::string& hosts, const std::string& modules,
                        const std::string& connections, const std::string& extra = "") {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"jobs\" version=\"1\">\n"
         "  <hosts>\n" +
         hosts + "  </hosts>\n" + extra + "  <modules>\n" + modules +
         "  </modules>\n  <connections>\n" + connections + "  </connections>\n</application>\n";
}

const std::string kOneHost = "    <host id=\"local\" address=\"127.0.0.1\"/>\n";

// An mpitest/rank module of MPI job `job` (none when empty) on `host`.
std::string rankModule(const std::string& id, const std::string& job,
                       const std::string& host = "local", const std::string& more = "") {
  return "    <module id=\"" + id + "\" package=\"mpitest\" type=\"rank\" host=\"" + host +
         "\">\n" + (job.empty() ? "" : "      <param name=\"job\" value=\"" + job + "\"/>\n") +
         more + "    </module>\n";
}

// A core/recorder of module `id`'s output, writing `csv`, and its connection.
std::string recorder(const std::string& id, const std::string& csv,
                     const std::string& host = "local") {
  return "    <module id=\"rec-" + id + "\" package=\"core\" type=\"recorder\" host=\"" + host +
         "\">\n      <param name=\"file\" value=\"" + csv + "\"/>\n    </module>\n";
}
std::string recorded(const std::string& id) {
  return "    <connection from=\"" + id + ".out\" to=\"rec-" + id + ".in\"/>\n";
}

// What one module put per iteration, as its recorder wrote it.
struct Seen {
  std::string source;  ///< the module id in the message's stamps
  int rank = -1, size = -1, rankSum = -1;
};

// The rows of a core/recorder CSV: iteration,source,source_iteration,sim_time,kind,id,x,y,z.
std::vector<Seen> readRecording(const std::string& path) {
  std::vector<Seen> rows;
  for (const auto& cells : readCsvRows(path)) {
    if (cells.size() < 9 || cells[4] != "object") continue;
    rows.push_back({cells[1], std::stoi(cells[6]), std::stoi(cells[7]), std::stoi(cells[8])});
  }
  return rows;
}

// An mpirun for VRFLOW_MPIRUN in `dir`: it appends its arguments to dir/mpirun.log and runs the
// real mpirun.
std::string loggingMpirun(const TempDir& dir) {
  const auto wrapper = dir.write(
      "mpirun", "#!/bin/sh\necho \"$@\" >> '" + dir.file("mpirun.log") + "'\nexec mpirun \"$@\"\n");
  EXPECT_EQ(chmod(wrapper.c_str(), 0755), 0);
  return wrapper;
}

// After a rank died, mpirun ends the job's other ranks and exits without waiting for each of
// them: they end with it (Module::init() set their parent-death signal) and come back to this
// test, a subreaper. Waits (at most `seconds`) until no child of this test still runs, reaping
// those that ended; what still runs then is left for leftoverProcesses() to report.
void reapRanksEndingAfterMpirun(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    bool running = false;
    for (const ProcessInfo& process : processTable()) {
      if (process.parent == getpid() && process.state != 'Z') running = true;
    }
    while (waitpid(-1, nullptr, WNOHANG) > 0) {
    }
    if (!running) return;
    usleep(20000);
  }
}

class MpiJobRun : public ::testing::Test {
 protected:
  void TearDown() override {
    unsetenv("VRFLOW_MPIRUN");
    const auto left = leftoverProcesses();
    EXPECT_TRUE(left.empty()) << "processes were left behind: " << left.front();
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

// Three modules of job `water` and one of job `air` (the same type, another value): the three
// are the ranks of one `mpirun -np 3`, in the application's module order (the `air` module
// between them takes no rank), and `air` runs alone as an MPI singleton of size 1.
TEST_F(MpiJobRun, ModulesOfOneJobAreTheRanksOfOneMpirunInModuleOrder) {
  const std::vector<std::string> ids{"b0", "solo", "b1", "b2"};
  std::string modules, connections;
  for (const auto& id : ids) {
    modules += rankModule(id, id == "solo" ? "air" : "water");
    connections += recorded(id);
  }
  for (const auto& id : ids) modules += recorder(id, dir.file(id + ".csv"));
  const auto file = dir.write("jobs.xml", application(kOneHost, modules, connections));
  setenv("VRFLOW_MPIRUN", loggingMpirun(dir).c_str(), 1);
  const auto result = runVrflow({"run", file, "--iterations", "6", "--no-progress", "--report",
                                 dir.file("report.json"), "--log-dir", dir.file("logs")},
                                120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  // mpirun tags each line with its rank: rank r's lines go to the log of the job's module r.
  for (const auto& [id, line] :
       std::map<std::string, std::string>{{"b0", "joined as rank 0 of 3"},
                                          {"b1", "joined as rank 1 of 3"},
                                          {"b2", "joined as rank 2 of 3"},
                                          {"solo", "joined as rank 0 of 1"}}) {
    const auto lines = readLines(dir.file("logs/" + id + ".log"));
    EXPECT_NE(std::find(lines.begin(), lines.end(), line), lines.end()) << id << ": " << line;
    EXPECT_NE(result.err.find("[" + id + "@"), std::string::npos) << result.err;
  }

  const std::map<std::string, Seen> expected{{"b0", {"b0", 0, 3, 3}},
                                             {"b1", {"b1", 1, 3, 3}},
                                             {"b2", {"b2", 2, 3, 3}},
                                             {"solo", {"solo", 0, 1, 0}}};
  for (const auto& [id, want] : expected) {
    const auto rows = readRecording(dir.file(id + ".csv"));
    ASSERT_EQ(rows.size(), 6u) << id;
    for (const Seen& row : rows) {
      EXPECT_EQ(row.source, want.source) << id;
      EXPECT_EQ(row.rank, want.rank) << id;
      EXPECT_EQ(row.size, want.size) << id;
      EXPECT_EQ(row.rankSum, want.rankSum) << id;
    }
  }
  // The ranks' object ids carry their modules' prefixes (docs/message-layout.md, "Ids"): the
  // ranks of one job never make the same id.
  std::set<std::uint64_t> prefixes;
  for (const auto& id : ids) {
    const auto rows = readCsvRows(dir.file(id + ".csv"));
    ASSERT_FALSE(rows.empty()) << id;
    const std::uint64_t object = std::stoull(rows.front()[5]);
    EXPECT_EQ(object >> 32, msg::fnv1a32(id)) << id;
    prefixes.insert(object >> 32);
  }
  EXPECT_EQ(prefixes.size(), ids.size());
  // One mpirun, for the job of three; its ranks get the modules' slots, not a module of their own.
  const auto calls = readLines(dir.file("mpirun.log"));
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_NE(calls[0].find("-np 3"), std::string::npos) << calls[0];
  EXPECT_NE(calls[0].find("-x VRFLOW_MODULE_INDICES"), std::string::npos) << calls[0];
  EXPECT_NE(calls[0].find("-x VRFLOW_SEGMENT_PATH"), std::string::npos) << calls[0];
  EXPECT_EQ(calls[0].find("VRFLOW_MPI_RANKS"), std::string::npos) << calls[0];
  EXPECT_NE(calls[0].find("vrflow-mpitest-rank"), std::string::npos) << calls[0];
  // The report lists every module once, each with the iterations it ran.
  const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
  EXPECT_EQ(report["status"], "ok");
  ASSERT_EQ(report["modules"].size(), 8u);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    EXPECT_EQ(report["modules"][i]["id"], ids[i]);
    EXPECT_EQ(report["modules"][i]["iterations"], 6) << ids[i];
    EXPECT_EQ(report["modules"][i]["exit"], "status 0") << ids[i];
  }
}

// The lead case of composites: each instance names its own job with ${instance}, so two
// instances of a two-block composite are two jobs of two ranks each, nested ones too.
TEST_F(MpiJobRun, EachCompositeInstanceNamesItsOwnJob) {
  const std::string composites = R"(  <composites>
    <composite name="blocks">
      <param name="out" default=""/>
      <modules>
        <repeat var="b" count="2">
          <module id="b${b}" package="mpitest" type="rank">
            <param name="job" value="${instance}"/>
          </module>
          <module id="rec${b}" package="core" type="recorder">
            <param name="file" value="${out}-${b}.csv"/>
          </module>
        </repeat>
      </modules>
      <connections>
        <repeat var="b" count="2">
          <connection from="b${b}.out" to="rec${b}.in"/>
        </repeat>
      </connections>
    </composite>
  </composites>
)";
  std::string instances = "  <instances>\n";
  for (const char* id : {"water", "air"}) {
    instances += "    <instance id=\"" + std::string(id) + "\" composite=\"blocks\">\n" +
                 "      <param name=\"out\" value=\"" + dir.file(id) + "\"/>\n    </instance>\n";
  }
  instances += "  </instances>\n";
  std::string text = application(kOneHost, "", "", composites);
  text.replace(text.rfind("  <connections>"), 0, instances);
  const auto file = dir.write("composed.xml", text);
  const auto result = runVrflow({"run", file, "--iterations", "4", "--no-progress"}, 120);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  for (const char* id : {"water", "air"}) {
    for (int b = 0; b < 2; ++b) {
      const auto rows = readRecording(dir.file(std::string(id) + "-" + std::to_string(b) + ".csv"));
      ASSERT_EQ(rows.size(), 4u) << id << b;
      EXPECT_EQ(rows[0].source, std::string(id) + ":b" + std::to_string(b));
      EXPECT_EQ(rows[0].rank, b) << id;
      EXPECT_EQ(rows[0].size, 2) << id;
      EXPECT_EQ(rows[0].rankSum, 1) << id;
    }
  }
}

// Cross-host MPI jobs are not supported (yet): `vrflow validate` names the job, its modules and
// their hosts at the module on the other host.
TEST_F(MpiJobRun, AJobOnTwoHostsIsRefusedByValidate) {
  const std::string hosts = kOneHost + "    <host id=\"b\" address=\"127.0.0.2\"/>\n";
  const auto file =
      dir.write("split.xml",
                application(hosts, rankModule("b0", "water") + rankModule("b1", "water", "b"), ""));
  for (const char* command : {"validate", "run"}) {
    const auto result = runVrflow({command, file}, 60);
    EXPECT_NE(result.exitCode, 0) << command;
    EXPECT_NE(result.err.find(file + ":11:"), std::string::npos) << command << ": " << result.err;
    EXPECT_NE(result.err.find("module 'b1' is on host 'b' but MPI job 'water' (mpitest/rank) began "
                              "on host 'local' (b0 on host 'local'; b1 on host 'b')"),
              std::string::npos)
        << command << ": " << result.err;
    EXPECT_NE(result.err.find("MPI jobs across hosts are not supported yet"), std::string::npos)
        << result.err;
  }
}

// Without mpirun (VRFLOW_MPIRUN=none) the ranks of a job cannot start: the run fails before
// starting anything, naming the job and its modules.
TEST_F(MpiJobRun, WithoutMpirunAJobOfTwoModulesFailsAtStartNamingIt) {
  const auto file =
      dir.write("none.xml", application(kOneHost,
                                        rankModule("b0", "water") + rankModule("b1", "water") +
                                            recorder("b0", dir.file("b0.csv")) +
                                            recorder("b1", dir.file("b1.csv")),
                                        recorded("b0") + recorded("b1")));
  setenv("VRFLOW_MPIRUN", "none", 1);
  const auto result = runVrflow({"run", file, "--iterations", "5", "--no-progress"}, 60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("MPI job 'water' (modules b0, b1; host local) cannot start: "
                            "VRFLOW_MPIRUN=none"),
            std::string::npos)
      << result.err;
  EXPECT_FALSE(std::ifstream(dir.file("b0.csv")).good()) << "a recorder was started";
}

// A launcher that cannot be run: one error naming the job and the launcher; the modules
// already started (the recorders, first in the file) are stopped.
TEST_F(MpiJobRun, AMissingMpirunIsAClearErrorNamingTheJob) {
  const auto file = dir.write(
      "missing.xml",
      application(kOneHost,
                  recorder("b0", dir.file("b0.csv")) + recorder("b1", dir.file("b1.csv")) +
                      rankModule("b0", "water") + rankModule("b1", "water"),
                  recorded("b0") + recorded("b1")));
  setenv("VRFLOW_MPIRUN", "/nonexistent/mpirun", 1);
  const auto result = runVrflow({"run", file, "--iterations", "5", "--no-progress"}, 60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("MPI job 'water' (modules b0, b1; host local): cannot start "
                            "'/nonexistent/mpirun'"),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("an MPI job of 2 modules is started through mpirun"), std::string::npos)
      << result.err;
}

// A rank that dies (SIGKILL at its iteration 3) ends its mpirun, which ends the job's other
// modules and the run: one error naming the job, long before --timeout would end the run.
TEST_F(MpiJobRun, ARankThatDiesEndsTheRunNamingTheJob) {
  std::string modules, connections;
  for (const char* id : {"b0", "b1", "b2"}) {
    modules +=
        rankModule(id, "water", "local",
                   std::string(id) == "b1" ? "      <param name=\"crash-at\" value=\"3\"/>\n" : "");
    modules += recorder(id, dir.file(std::string(id) + ".csv"));
    connections += recorded(id);
  }
  const auto file = dir.write("crash.xml", application(kOneHost, modules, connections));
  const auto result = runVrflow(
      {"run", file, "--timeout", "100", "--no-progress", "--report", dir.file("report.json")}, 150);
  EXPECT_EQ(result.exitCode, 1) << "1: failed (3 would be the timeout): " << result.err;
  reapRanksEndingAfterMpirun(5);
  EXPECT_NE(result.err.find("MPI job 'water' (modules b0, b1, b2; host local; mpirun pid "),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("an MPI rank was killed by signal 9"), std::string::npos) << result.err;
  const auto report = nlohmann::json::parse(readFile(dir.file("report.json")));
  EXPECT_EQ(report["status"], "failed");
  ASSERT_EQ(report["modules"].size(), 6u);
  // The three modules share one end: their mpirun's.
  const auto exit = report["modules"][0]["exit"];
  EXPECT_NE(exit, "status 0");
  EXPECT_EQ(report["modules"][2]["exit"], exit);
  EXPECT_EQ(report["modules"][4]["exit"], exit);
}

// A process of an MPI job finds its module by its MPI rank: without a rank, or with one the
// job's indices do not cover, it refuses to join, saying why (before touching the run).
TEST(MpiJobModule, ARankWithoutItsEntryInTheJobCannotJoin) {
  const std::string relay = binDir() + "/vrflow-core-relay";
  setenv("VRFLOW_SEGMENT_PATH", "/nonexistent", 1);
  setenv("VRFLOW_MPI_JOB", "water", 1);
  const std::vector<std::pair<std::string, std::string>> cases{
      {"",
       "is a module of MPI job 'water' (VRFLOW_MODULE_INDICES=4,7) but has no MPI rank "
       "(neither OMPI_COMM_WORLD_RANK nor PMIX_RANK is set)"},
      {"2",
       "MPI rank 2 (OMPI_COMM_WORLD_RANK) is not a rank of MPI job 'water', which has 2 "
       "module(s) (VRFLOW_MODULE_INDICES=4,7)"},
      {"x", "MPI rank x (OMPI_COMM_WORLD_RANK) is not a rank"}};
  for (const auto& [rank, expected] : cases) {
    setenv("VRFLOW_MODULE_INDICES", "4,7", 1);
    if (!rank.empty()) setenv("OMPI_COMM_WORLD_RANK", rank.c_str(), 1);
    const auto result = runCommand({relay}, 30);
    unsetenv("OMPI_COMM_WORLD_RANK");
    EXPECT_NE(result.exitCode, 0) << rank;
    EXPECT_NE(result.err.find("cannot join the run: "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(expected), std::string::npos) << result.err;
  }
  setenv("VRFLOW_MODULE_INDICES", "4,,7", 1);
  setenv("OMPI_COMM_WORLD_RANK", "0", 1);
  const auto malformed = runCommand({relay}, 30);
  EXPECT_NE(malformed.err.find("malformed VRFLOW_MODULE_INDICES '4,,7'"), std::string::npos)
      << malformed.err;
  for (const char* name :
       {"VRFLOW_SEGMENT_PATH", "VRFLOW_MPI_JOB", "VRFLOW_MODULE_INDICES", "OMPI_COMM_WORLD_RANK"}) {
    unsetenv(name);
  }
}

}  // namespace
}  // namespace vrflow::testing
