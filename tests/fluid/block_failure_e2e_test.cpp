#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../runtime/process_helpers.hpp"

// A fluid of 2 MPI blocks, through `vrflow run`, whose worker block dies or whose step fails on
// one block or on every block: as one module of 2 ranks (mpi-ranks="blocks": vrflow starts it
// through mpirun) and as two modules of one MPI job (the composite fluid_blocks). The failures
// are real: a SIGKILL, or a body whose angular velocity is not a number (the test box's
// `broken-at`), which the solver refuses on every block that couples the body. The run must end
// with an error naming the module or the job, well before its --timeout, leaving no process and
// no shared memory behind.
namespace vrflow::testing {
namespace {

constexpr double kTimeoutSeconds = 300;  // the run's --timeout: a hang would reach it
constexpr double kBoundSeconds = 60;     // how long the test waits before calling it a hang

// The tank (8 x 8 x 8 cells of 0.1 m: 2 blocks of 4 z-planes) and the test box in it.
struct Tank {
  bool asJob = false;  ///< two modules of one MPI job (fluid_blocks), else one module of 2 ranks
  std::string boxStart = "0.4 0.45 0.4";  ///< at z = 0.4 the box spans both blocks' slabs
  std::string boxHalf = "0.15";
  int brokenAt = 0;  ///< the box's broken-at: its angular velocity is NaN from this iteration
};

// The tank with its stats written to `stats` every iteration and a box floating in it.
std::string twoBlockTank(const std::string& stats, const Tank& tank) {
  // The tank's parameters; a composite spells '-' as '_'.
  const std::string dash = tank.asJob ? "_" : "-";
  const std::string params = R"(      <param name="nx" value="8"/>
      <param name="ny" value="8"/>
      <param name="nz" value="8"/>
      <param name="cell)" + dash +
                             R"(size" value="0.1"/>
      <param name="fill)" + dash +
                             R"(max" value="0.8 0.4 0.8"/>
      <param name="blocks" value="2"/>
      <param name="stats" value=")" +
                             stats + R"("/>
)";
  const std::string box = R"(    <module id="box" package="fluidtest" type="box" host="local">
      <param name="half" value=")" +
                          tank.boxHalf + R"("/>
      <param name="start" value=")" +
                          tank.boxStart + R"("/>
      <param name="broken-at" value=")" +
                          std::to_string(tank.brokenAt) + R"("/>
      <param name="trajectory" value=")" +
                          stats + R"(.box.csv"/>
      <input port="events" initial-messages="1"/>
    </module>
)";
  const std::string fluid =
      tank.asJob ? R"(  <instances>
    <instance id="water" composite="fluid_blocks" host="local">
)" + params + R"(    </instance>
  </instances>
)"
                 : R"(    <module id="water" package="fluid" type="fluid" host="local">
)" + params + R"(    </module>
)";
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="fluid-block-failure" version="1">
  <hosts>
    <host id="local" address="127.0.0.1"/>
  </hosts>
  <modules>
)" + box +
         (tank.asJob ? "" : fluid) + "  </modules>\n" + (tank.asJob ? fluid : "") +
         R"(  <connections>
    <connection from="box.objects" to="water.objects"/>
    <connection from="water.forces" to="box.events"/>
  </connections>
</application>
)";
}

// What vrflow calls the fluid when it reports its end.
std::string fluidName(bool asJob) {
  return asJob ? "MPI job 'water' (modules water:block0, water:block1" : "module 'water'";
}

std::string readProcFile(pid_t pid, const char* name) {
  return readFile("/proc/" + std::to_string(pid) + "/" + name);
}

// The NUL-separated entries of /proc/PID/cmdline or /proc/PID/environ.
std::vector<std::string> procEntries(pid_t pid, const char* name) {
  std::vector<std::string> entries;
  std::stringstream in(readProcFile(pid, name));
  for (std::string entry; std::getline(in, entry, '\0');) entries.push_back(entry);
  return entries;
}

std::string environValue(pid_t pid, const std::string& variable) {
  for (const auto& entry : procEntries(pid, "environ")) {
    if (entry.rfind(variable + "=", 0) == 0) return entry.substr(variable.size() + 1);
  }
  return {};
}

// Every live process under `root` (children, their children, ...).
std::vector<pid_t> descendantsOf(pid_t root) {
  std::multimap<pid_t, pid_t> children;
  for (const ProcessInfo& process : processTable()) {
    if (process.state != 'Z') children.emplace(process.parent, process.pid);
  }
  std::vector<pid_t> found{root};
  for (std::size_t i = 0; i < found.size(); ++i) {
    const auto [begin, end] = children.equal_range(found[i]);
    for (auto it = begin; it != end; ++it) found.push_back(it->second);
  }
  found.erase(found.begin());
  return found;
}

// The fluid's worker block under `vrflow`: the vrflow-fluid that is rank 1 of mpirun's job. 0 if
// there is none (yet).
pid_t workerBlock(pid_t vrflow) {
  for (const pid_t pid : descendantsOf(vrflow)) {
    const auto args = procEntries(pid, "cmdline");
    if (args.empty() || std::filesystem::path(args[0]).filename() != "vrflow-fluid") continue;
    if (environValue(pid, "OMPI_COMM_WORLD_RANK") == "1") return pid;
  }
  return 0;
}

// Open MPI names its shared-memory files with the job id in hex; the jobs of one mpirun share the
// upper 16 bits, the job family.
std::string jobFamilyHex(const std::string& jobid) {
  std::ostringstream hex;
  hex << std::hex << (std::strtoul(jobid.c_str(), nullptr, 10) >> 16);
  return hex.str();
}

// Entries of /dev/shm not in `before` that belong to the run of `vrflow`: vrflow's, the folder
// of its MPI jobs' shared memory (ompi-job.PID.*), or Open MPI's files of the job family
// `family` when known (other tests may run MPI jobs meanwhile).
std::vector<std::string> runShmEntries(const std::set<std::string>& before, pid_t vrflow,
                                       const std::string& family) {
  std::vector<std::string> found = vrflowShmEntries();
  const std::string backing = "ompi-job." + std::to_string(vrflow) + ".";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/shm", ec)) {
    const auto name = entry.path().filename().string();
    if (before.count(name)) continue;
    if (name.rfind(backing, 0) == 0 ||
        (!family.empty() && name.find("." + family) != std::string::npos)) {
      found.push_back(name);
    }
  }
  return found;
}

std::set<std::string> shmNow() {
  std::set<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/shm", ec)) {
    names.insert(entry.path().filename().string());
  }
  return names;
}

// Reaps this process's exited children and waits (at most `seconds`) until none is left: after a
// rank died or aborted, mpirun ends the job's other ranks and exits without waiting for each of
// them; they come back to this test (a child subreaper) and end a moment later. What is left
// after that is reported by leftoverProcesses().
void waitForOrphansToEnd(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    while (waitpid(-1, nullptr, WNOHANG) > 0) {
    }
    // Zombies are not descendants here: one that ended since the reaping above is reaped now,
    // or leftoverProcesses() would count it.
    if (descendantsOf(getpid()).empty()) {
      while (waitpid(-1, nullptr, WNOHANG) > 0) {
      }
      return;
    }
    usleep(50000);
  }
}

// Waits (at most `seconds`) for `pid` to end; its wait status, or nothing if it still runs.
std::optional<int> waitForExit(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    usleep(20000);
  }
  return std::nullopt;
}

// `vrflow run APP --timeout 300` in the background, its stderr to `errPath`.
pid_t startRun(const std::string& app, const std::string& errPath) {
  const std::string vrflow = binDir() + "/vrflow";
  const std::string packages = binDir() + "/../test-packages";
  const std::string timeout = std::to_string(kTimeoutSeconds);
  const pid_t pid = fork();
  if (pid == 0) {
    freopen("/dev/null", "w", stdout);
    freopen(errPath.c_str(), "w", stderr);
    execl(vrflow.c_str(), vrflow.c_str(), "--packages", packages.c_str(), "run", app.c_str(),
          "--timeout", timeout.c_str(), "--no-progress", static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// Runs `tank` through `vrflow run` (mpirun from PATH) and checks its end: vrflow exits with
// status 1 within kBoundSeconds (not by its --timeout), naming the fluid, and leaves no process
// and no /dev/shm entry of the run. With `killWorker`, once the run steps (its buffered stats
// file has been written to) the worker block, rank 1, is killed with SIGKILL; otherwise the tank
// must fail on its own (its box's broken-at). Returns vrflow's stderr.
std::string runUntilItEnds(const Tank& tank, bool killWorker) {
  unsetenv("VRFLOW_MPIRUN");
  TempDir dir;
  const auto stats = dir.file("stats.csv");
  const auto app = dir.write("tank.xml", twoBlockTank(stats, tank));
  const auto before = shmNow();
  const pid_t vrflow = startRun(app, dir.file("err.txt"));
  const auto giveUp = [&](const std::string& why) {
    kill(vrflow, SIGKILL);
    waitpid(vrflow, nullptr, 0);
    leftoverProcesses();
    ADD_FAILURE() << why << "\n" << readFile(dir.file("err.txt"));
    return std::string();
  };

  std::string family;  // of the run's MPI job, when its worker block was seen
  if (killWorker) {
    pid_t worker = 0;
    const auto stepping = std::chrono::steady_clock::now();
    for (;;) {
      std::error_code ec;
      const auto written = std::filesystem::file_size(stats, ec);
      worker = !ec && written > 0 ? workerBlock(vrflow) : 0;
      if (worker > 0) break;
      if (waitpid(vrflow, nullptr, WNOHANG) == vrflow) {
        ADD_FAILURE() << "the run ended before stepping\n" << readFile(dir.file("err.txt"));
        return {};
      }
      if (std::chrono::steady_clock::now() - stepping > std::chrono::seconds(60)) {
        return giveUp("not stepping with a worker block after 60 s");
      }
      usleep(50000);
    }
    family = jobFamilyHex(environValue(worker, "OMPI_MCA_ess_base_jobid"));
    EXPECT_FALSE(family.empty() || family == "0") << "no Open MPI job id";
    EXPECT_EQ(kill(worker, SIGKILL), 0);
  }

  const auto status = waitForExit(vrflow, kBoundSeconds);
  if (!status) return giveUp("vrflow still runs 60 s after the failure (hang)");
  const auto err = readFile(dir.file("err.txt"));
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 1) << err;
  EXPECT_NE(err.find(fluidName(tank.asJob)), std::string::npos) << err;
  EXPECT_EQ(err.find("timed out"), std::string::npos) << err;
  waitForOrphansToEnd(10);
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << left.front();
  const auto shm = runShmEntries(before, vrflow, family);
  EXPECT_TRUE(shm.empty()) << shm.front();
  return err;
}

// What the solver says of the test box's zero orientation (its body id varies).
constexpr const char* kRefusedBody = "orientation quaternion is zero";

// A tank whose box turns broken (a zero orientation) at iteration 10 at `start`: at z = 0.4 the
// box, 0.3 m wide, meets both blocks' slabs; at z = 0.7, 0.1 m wide (z from 0.65 to 0.75), only
// block 1's (z >= 0.4, with the 2-cell margin from 0.2): block 0 (z < 0.4, to 0.6 with the
// margin) neither receives it from the route filter nor couples it.
Tank brokenBoxTank(bool asJob, const std::string& start = "0.4 0.45 0.4",
                   const std::string& half = "0.15") {
  Tank tank;
  tank.asJob = asJob;
  tank.boxStart = start;
  tank.boxHalf = half;
  tank.brokenAt = 10;
  return tank;
}

TEST(FluidModule, WorkerBlockKilledUnderMpirunEndsTheRunPromptly) {
  const auto err = runUntilItEnds(Tank{}, true);
  // mpirun ends the job (rank 0 included) and exits with 128 + 9.
  EXPECT_NE(err.find("an MPI rank was killed by signal 9"), std::string::npos) << err;
}

// One module of 2 ranks: rank 0 broadcasts the bodies, so every block checks the same input and
// a bad body fails the step on every block together (a block cannot fail alone without a bug).
TEST(FluidModule, StepFailingOnEveryBlockIsReportedByTheModuleAlone) {
  const auto err = runUntilItEnds(brokenBoxTank(false), false);
  // The blocks agree that they all failed: rank 0 reports it, no block aborts the job.
  EXPECT_NE(err.find("vrflow-fluid: fluid: body "), std::string::npos) << err;
  EXPECT_NE(err.find(kRefusedBody), std::string::npos) << err;
  EXPECT_EQ(err.find("alone"), std::string::npos) << err;
  EXPECT_EQ(err.find("MPI_ABORT"), std::string::npos) << err;
}

// The same with the fluid as two modules of one MPI job (fluid_blocks): the blocks are peers,
// mpirun is the job's one process, and vrflow names the job. Each block couples only the bodies
// near its slab, so a bad body near one slab fails that block alone.
TEST(FluidBlocksJob, ABlockKilledEndsTheRunPromptlyNamingTheJob) {
  Tank tank;
  tank.asJob = true;
  const auto err = runUntilItEnds(tank, true);
  EXPECT_NE(err.find("an MPI rank was killed by signal 9"), std::string::npos) << err;
}

TEST(FluidBlocksJob, ABlockWhoseStepFailsAloneAbortsTheJobPromptly) {
  const auto err = runUntilItEnds(brokenBoxTank(true, "0.4 0.45 0.7", "0.05"), false);
  EXPECT_NE(err.find("MPI block 1 of 2 (job 'water') failed alone: fluid: body "),
            std::string::npos)
      << err;
  EXPECT_NE(err.find(kRefusedBody), std::string::npos) << err;
  EXPECT_EQ(err.find("MPI block 0 of 2"), std::string::npos) << "block 0 did not fail: " << err;
}

TEST(FluidBlocksJob, AStepFailingOnEveryBlockEndsTheRunWithoutAnAbort) {
  const auto err = runUntilItEnds(brokenBoxTank(true), false);
  EXPECT_NE(err.find("vrflow-fluid: fluid: body "), std::string::npos) << err;
  EXPECT_NE(err.find(kRefusedBody), std::string::npos) << err;
  EXPECT_EQ(err.find("alone"), std::string::npos) << err;
  EXPECT_EQ(err.find("MPI_ABORT"), std::string::npos) << err;
}

}  // namespace
}  // namespace vrflow::testing
