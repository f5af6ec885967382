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

// A fluid of 2 MPI blocks whose worker block dies or fails alone, through `vrflow run`, started
// both ways (by vrflow through mpirun, and spawned by the module with VRFLOW_MPIRUN=none): the
// run must end with an error naming the module, well before its --timeout, leaving no process
// and no shared memory behind.
namespace vrflow::testing {
namespace {

constexpr double kTimeoutSeconds = 300;  // the run's --timeout: a hang would reach it
constexpr double kBoundSeconds = 60;     // how long the test waits before calling it a hang

// A small tank in 2 blocks (4 z-planes each), with its stats written to `stats` every iteration:
// the module's own blocks, or (`asJob`) two modules of one MPI job (the composite fluid_blocks).
std::string twoBlockTank(const std::string& stats, bool asJob = false) {
  // The tank's parameters; a composite spells '-' as '_'.
  const std::string dash = asJob ? "_" : "-";
  const std::string params = R"(      <param name="nx" value="8"/>
      <param name="ny" value="8"/>
      <param name="nz" value="8"/>
      <param name="cell)" + dash + R"(size" value="0.1"/>
      <param name="fill)" + dash + R"(max" value="0.8 0.4 0.8"/>
      <param name="blocks" value="2"/>
      <param name="stats" value=")" + stats + R"("/>
)";
  const std::string header = R"(<?xml version="1.0" encoding="UTF-8"?>
<application name="fluid-block-failure" version="1">
  <hosts>
    <host id="local" address="127.0.0.1"/>
  </hosts>
)";
  if (!asJob) {
    return header + R"(  <modules>
    <module id="water" package="fluid" type="fluid" host="local">
)" + params + R"(    </module>
  </modules>
</application>
)";
  }
  // The composite's objects input feeds a route filter, which must be connected: a box floats.
  return header + R"(  <modules>
    <module id="box" package="fluidtest" type="box" host="local">
      <param name="half" value="0.15"/>
      <param name="start" value="0.4 0.45 0.4"/>
      <param name="trajectory" value=")" +
         stats + R"(.box.csv"/>
      <input port="events" initial-messages="1"/>
    </module>
  </modules>
  <instances>
    <instance id="water" composite="fluid_blocks" host="local">
)" + params + R"(    </instance>
  </instances>
  <connections>
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

// The fluid's worker block under `vrflow`: the vrflow-fluid that is rank 1 of mpirun's job, or
// the one the module spawned with --block-worker. 0 if there is none (yet).
pid_t workerBlock(pid_t vrflow) {
  for (const pid_t pid : descendantsOf(vrflow)) {
    const auto args = procEntries(pid, "cmdline");
    if (args.empty() || std::filesystem::path(args[0]).filename() != "vrflow-fluid") continue;
    const bool spawned = args.size() > 1 && args[1] == "--block-worker";
    if (spawned || environValue(pid, "OMPI_COMM_WORLD_RANK") == "1") return pid;
  }
  return 0;
}

// Open MPI names its shared-memory files with the job id in hex; the jobs of one run (mpirun's,
// or the singleton's and its spawned one) share the upper 16 bits, the job family.
std::string jobFamilyHex(const std::string& jobid) {
  std::ostringstream hex;
  hex << std::hex << (std::strtoul(jobid.c_str(), nullptr, 10) >> 16);
  return hex.str();
}

// Entries of /dev/shm not in `before` that belong to the run: vrflow's, or Open MPI's of the
// job family `family` (other tests may run MPI jobs meanwhile).
std::vector<std::string> runShmEntries(const std::set<std::string>& before,
                                       const std::string& family) {
  std::vector<std::string> found = vrflowShmEntries();
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/shm", ec)) {
    const auto name = entry.path().filename().string();
    if (!before.count(name) && !family.empty() && name.find("." + family) != std::string::npos) {
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

// Reaps this process's exited children and waits (at most `seconds`) until none is left: the
// spawn path's orted ends a moment after the module, as orphans handed to this test (a child
// subreaper). What is left after that is reported by leftoverProcesses().
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

// Runs the two-block tank with `launcher` as VRFLOW_MPIRUN, kills the worker block (rank 1) with
// SIGKILL once the run steps (or as soon as the worker is there, `whileStarting`), and checks
// the end; returns vrflow's stderr.
std::string killWorkerBlock(const char* launcher, bool whileStarting = false, bool asJob = false) {
  unsetenv("OMPI_MCA_btl");  // spawned ranks talk over TCP: leave the choice to Open MPI
  setenv("VRFLOW_MPIRUN", launcher, 1);
  TempDir dir;
  const auto stats = dir.file("stats.csv");
  const auto app = dir.write("tank.xml", twoBlockTank(stats, asJob));
  const auto before = shmNow();
  const pid_t vrflow = startRun(app, dir.file("err.txt"));
  unsetenv("VRFLOW_MPIRUN");
  const auto giveUp = [&](const std::string& why) {
    kill(vrflow, SIGKILL);
    waitpid(vrflow, nullptr, 0);
    leftoverProcesses();
    ADD_FAILURE() << launcher << ": " << why << "\n" << readFile(dir.file("err.txt"));
    return std::string();
  };

  // Stepping: the stats file (buffered) has been written to, and the worker is there.
  pid_t worker = 0;
  const auto stepping = std::chrono::steady_clock::now();
  for (;;) {
    std::error_code ec;
    const auto written = std::filesystem::file_size(stats, ec);
    worker = whileStarting || (!ec && written > 0) ? workerBlock(vrflow) : 0;
    if (worker > 0) break;
    if (waitpid(vrflow, nullptr, WNOHANG) == vrflow) {
      ADD_FAILURE() << launcher << ": the run ended before stepping\n"
                    << readFile(dir.file("err.txt"));
      return {};
    }
    if (std::chrono::steady_clock::now() - stepping > std::chrono::seconds(60)) {
      return giveUp("not stepping with a worker block after 60 s");
    }
    usleep(50000);
  }
  const auto family = jobFamilyHex(environValue(worker, "OMPI_MCA_ess_base_jobid"));
  EXPECT_FALSE(family.empty() || family == "0") << launcher << ": no Open MPI job id";
  EXPECT_EQ(kill(worker, SIGKILL), 0);

  const auto status = waitForExit(vrflow, kBoundSeconds);
  if (!status) return giveUp("vrflow still runs 60 s after its worker block was killed (hang)");
  const auto err = readFile(dir.file("err.txt"));
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 1) << launcher << ": " << err;
  EXPECT_NE(err.find(fluidName(asJob)), std::string::npos) << launcher << ": " << err;
  EXPECT_EQ(err.find("timed out"), std::string::npos) << launcher << ": " << err;
  waitForOrphansToEnd(10);
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << launcher << ": " << left.front();
  const auto shm = runShmEntries(before, family);
  EXPECT_TRUE(shm.empty()) << launcher << ": " << shm.front();
  return err;
}

TEST(FluidModule, WorkerBlockKilledUnderMpirunEndsTheRunPromptly) {
  const auto err = killWorkerBlock("mpirun");
  // mpirun ends the job (rank 0 included) and exits with 128 + 9.
  EXPECT_NE(err.find("an MPI rank was killed by signal 9"), std::string::npos) << err;
}

TEST(FluidModule, SpawnedWorkerBlockKilledEndsTheRunPromptly) {
  const auto err = killWorkerBlock("none");
  // Open MPI does not tell the module; its watch over the spawned workers does.
  EXPECT_NE(err.find("MPI block 1 of 2"), std::string::npos) << err;
  EXPECT_NE(err.find("ended unexpectedly"), std::string::npos) << err;
}

// Killed while the module is still in MPI_Comm_spawn, which would wait for it forever.
TEST(FluidModule, SpawnedWorkerBlockKilledWhileStartingEndsTheRunPromptly) {
  const auto err = killWorkerBlock("none", true);
  EXPECT_NE(err.find("vrflow-fluid: "), std::string::npos) << err;
  EXPECT_NE(err.find("stopping the module"), std::string::npos) << err;
}

// A block cannot fail alone unless it has a bug (the blocks check the same input): the failure
// is injected (VRFLOW_FLUID_TEST_FAIL="BLOCK STEP", read by the module's blocks only).
CommandResult runWithInjectedFailure(const char* launcher, const char* failure,
                                     bool asJob = false) {
  unsetenv("OMPI_MCA_btl");
  TempDir dir;
  const auto app = dir.write("tank.xml", twoBlockTank(dir.file("stats.csv"), asJob));
  setenv("VRFLOW_MPIRUN", launcher, 1);
  setenv("VRFLOW_FLUID_TEST_FAIL", failure, 1);
  // Past kBoundSeconds runCommand kills vrflow (exit code 128 + 9): a hang.
  auto result = runVrflow(
      {"run", app, "--timeout", std::to_string(kTimeoutSeconds), "--no-progress"}, kBoundSeconds);
  unsetenv("VRFLOW_FLUID_TEST_FAIL");
  unsetenv("VRFLOW_MPIRUN");
  EXPECT_EQ(result.exitCode, 1) << launcher << " (137: hung, killed by the test): " << result.err;
  EXPECT_NE(result.err.find(asJob ? "water:block" : "module 'water'"), std::string::npos)
      << launcher << ": " << result.err;
  EXPECT_NE(result.err.find("failure injected"), std::string::npos)
      << launcher << ": " << result.err;
  waitForOrphansToEnd(10);
  const auto left = leftoverProcesses();
  EXPECT_TRUE(left.empty()) << launcher << ": " << left.front();
  return result;
}

TEST(FluidModule, WorkerBlockWhoseStepFailsAloneEndsTheRunPromptly) {
  for (const char* launcher : {"mpirun", "none"}) {
    const auto result = runWithInjectedFailure(launcher, "1 10");
    EXPECT_NE(result.err.find("MPI block 1 of 2 failed alone"), std::string::npos)
        << launcher << ": " << result.err;
  }
}

TEST(FluidModule, StepFailingOnEveryBlockIsReportedByTheModuleAlone) {
  for (const char* launcher : {"mpirun", "none"}) {
    const auto result = runWithInjectedFailure(launcher, "-1 10");
    // The blocks agree that they all failed: rank 0 reports it, no block aborts the job.
    EXPECT_NE(result.err.find("vrflow-fluid: fluid: block 0: failure injected"), std::string::npos)
        << launcher << ": " << result.err;
    EXPECT_EQ(result.err.find("alone"), std::string::npos) << launcher << ": " << result.err;
    EXPECT_EQ(result.err.find("MPI_ABORT"), std::string::npos) << launcher << ": " << result.err;
  }
}

// The same with the fluid as two modules of one MPI job (fluid_blocks): the blocks are peers,
// mpirun is the job's one process, and vrflow names the job.
TEST(FluidBlocksJob, ABlockKilledEndsTheRunPromptlyNamingTheJob) {
  const auto err = killWorkerBlock("mpirun", false, true);
  EXPECT_NE(err.find("an MPI rank was killed by signal 9"), std::string::npos) << err;
}

TEST(FluidBlocksJob, ABlockWhoseStepFailsAloneAbortsTheJobPromptly) {
  const auto result = runWithInjectedFailure("mpirun", "1 10", true);
  EXPECT_NE(result.err.find("MPI block 1 of 2 (job 'water') failed alone"), std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find(fluidName(true)), std::string::npos) << result.err;
}

TEST(FluidBlocksJob, AStepFailingOnEveryBlockEndsTheRunWithoutAnAbort) {
  const auto result = runWithInjectedFailure("mpirun", "-1 10", true);
  EXPECT_NE(result.err.find("vrflow-fluid: fluid: block 0: failure injected"), std::string::npos)
      << result.err;
  EXPECT_EQ(result.err.find("alone"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("MPI_ABORT"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace vrflow::testing
