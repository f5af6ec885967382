// The slurm backend against a real Slurm that this test starts: munged with its own key and
// socket, slurmctld and three slurmd (nodes n1-n3, each on its own port and its own loopback
// address 127.0.0.1-3), all in a temporary folder with their own state, spool and pid files.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <thread>

#include "cluster_helpers.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// A TCP port of 127.0.0.1 free now.
const char* const kPrograms[] = {"/usr/sbin/munged",  "/usr/sbin/slurmctld", "/usr/sbin/slurmd",
                                 "/usr/bin/salloc",   "/usr/bin/sbatch",     "/usr/bin/srun",
                                 "/usr/bin/scontrol", "/usr/bin/squeue",     "/usr/bin/scancel",
                                 "/usr/bin/sinfo"};

std::string threeHostsFile() {
  return sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
}

// Why this machine cannot run the local Slurm, or "".
std::string whyNoSlurm() {
  if (geteuid() != 0) return "the local Slurm runs its daemons as root (slurmd starts jobs)";
  for (const char* program : kPrograms) {
    if (access(program, X_OK) != 0) {
      return std::string(program) +
             " is not installed (Debian: munge slurmctld slurmd slurm-client)";
    }
  }
  return "";
}

// munged, slurmctld and three slurmd, stopped (with what they started) on destruction.
class LocalSlurm {
 public:
  LocalSlurm() {
    chmod(dir_.path().c_str(), 0755);  // slurmd checks its spool's parents
    const std::string d = dir_.path();
    mkdir((d + "/munge").c_str(), 0700);
    mkdir((d + "/state").c_str(), 0700);
    std::random_device random;
    std::string key(1024, '\0');
    for (char& c : key) c = static_cast<char>(random());
    dir_.write("munge/key", key);
    chmod((d + "/munge/key").c_str(), 0400);
    char name[256] = {};
    gethostname(name, sizeof name - 1);
    std::string host = name;
    host = host.substr(0, host.find('.'));
    std::string nodes;
    for (int n = 1; n <= 3; ++n) {
      const std::string id = std::to_string(n);
      mkdir((d + "/spool-n" + id).c_str(), 0755);
      nodes += "NodeName=n" + id + " NodeHostname=" + host + " NodeAddr=127.0.0." + id +
               " Port=" + std::to_string(unusedPort()) + " CPUs=1\n";
    }
    conf_ = dir_.write("slurm.conf",
                       "ClusterName=vrflowtest\n"
                       "SlurmctldHost=" +
                           host +
                           "(127.0.0.1)\n"
                           "SlurmctldPort=" +
                           std::to_string(unusedPort()) +
                           "\n"
                           "SlurmUser=root\nSlurmdUser=root\n"
                           "AuthType=auth/munge\nCredType=cred/munge\n"
                           "AuthInfo=socket=" +
                           d +
                           "/munge/socket\n"
                           "StateSaveLocation=" +
                           d +
                           "/state\n"
                           "SlurmdSpoolDir=" +
                           d +
                           "/spool-%n\n"
                           "SlurmctldPidFile=" +
                           d +
                           "/slurmctld.pid\n"
                           "SlurmdPidFile=" +
                           d +
                           "/slurmd-%n.pid\n"
                           "SlurmctldLogFile=" +
                           d +
                           "/slurmctld.log\n"
                           "SlurmdLogFile=" +
                           d +
                           "/slurmd-%n.log\n"
                           "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n"
                           "SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\n"
                           "SchedulerType=sched/builtin\nJobCompType=jobcomp/none\n"
                           "JobAcctGatherType=jobacct_gather/none\n"
                           "AccountingStorageType=accounting_storage/none\n"
                           "MpiDefault=none\nReturnToService=2\nKillWait=2\n" +
                           nodes + "PartitionName=vrflow Nodes=n[1-3] Default=YES State=UP\n");
    setenv("SLURM_CONF", conf_.c_str(), 1);
    for (const char* variable : {"SLURM_JOB_ID", "SLURM_JOB_NODELIST", "SLURM_JOBID"}) {
      unsetenv(variable);
    }
    start({"/usr/sbin/munged", "-F", "-f", "--key-file=" + d + "/munge/key",
           "--socket=" + d + "/munge/socket", "--pid-file=" + d + "/munge/pid",
           "--seed-file=" + d + "/munge/seed", "--log-file=" + d + "/munge/log"},
          "munged");
    for (int i = 0; i < 100 && access((d + "/munge/socket").c_str(), F_OK) != 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    start({"/usr/sbin/slurmctld", "-D", "-i", "-f", conf_}, "slurmctld");
    for (int n = 1; n <= 3; ++n) {
      start({"/usr/sbin/slurmd", "-D", "-f", conf_, "-N", "n" + std::to_string(n)},
            "slurmd-n" + std::to_string(n));
    }
  }

  ~LocalSlurm() {
    for (const pid_t pid : pids_) kill(-pid, SIGTERM);
    for (int i = 0; i < 100 && running(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    for (const pid_t pid : pids_) kill(-pid, SIGKILL);
    for (const pid_t pid : pids_) waitpid(pid, nullptr, 0);
    leftoverProcesses();  // the slurmstepd that outlived their slurmd (we are their subreaper)
    unsetenv("SLURM_CONF");
  }

  // Waits (20 s at most) until the three nodes are idle; "" or what went wrong.
  std::string waitUntilIdle() const {
    std::string state;
    for (int i = 0; i < 200; ++i) {
      state = runCommand({"/usr/bin/sinfo", "--noheader", "--Node", "--format=%N %T"}, 5).out;
      if (state == "n1 idle\nn2 idle\nn3 idle\n") return "";
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return "the nodes are not idle after 20 s: '" + state + "'\nslurmctld.log:\n" +
           readFile(dir_.file("slurmctld.log")) + "\nslurmd-n1.log:\n" +
           readFile(dir_.file("slurmd-n1.log"));
  }

  // The job steps the cluster still runs, one "ID NAME" a line.
  std::string steps() const {
    return runCommand({"/usr/bin/squeue", "--noheader", "--steps", "--format=%i %j"}, 10).out;
  }

 private:
  void start(const std::vector<std::string>& args, const std::string& log) {
    const std::string logFile = dir_.file(log + ".out");
    const pid_t pid = fork();
    if (pid == 0) {
      setpgid(0, 0);
      prctl(PR_SET_PDEATHSIG, SIGKILL);  // the test killed: its cluster goes with it
      const int fd = open(logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      dup2(fd, 1);
      dup2(fd, 2);
      std::vector<char*> argv;
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    pids_.push_back(pid);
  }

  bool running() const {
    for (const pid_t pid : pids_) {
      if (waitpid(pid, nullptr, WNOHANG) == 0) return true;
    }
    return false;
  }

  TempDir dir_;
  std::string conf_;
  std::vector<pid_t> pids_;
};

// `salloc --nodes=N vrflow launch COPY --backend slurm ARGS...`, running in a thread meanwhile,
// of a copy of the example in `dir` (its daemons told apart from any other's by that path).
class SallocLaunch {
 public:
  SallocLaunch(const TempDir& dir, int nodes, const std::vector<std::string>& args)
      : appFile(dir.write("pipeline_3hosts.xml", readFile(threeHostsFile()))) {
    std::vector<std::string> argv{"/usr/bin/salloc", "--nodes=" + std::to_string(nodes),
                                  "--time=2",        binDir() + "/vrflow",
                                  "launch",          appFile,
                                  "--backend",       "slurm"};
    argv.insert(argv.end(), args.begin(), args.end());
    thread_ = std::thread([this, argv] { result_ = runCommand(argv, 60); });
  }
  ~SallocLaunch() { result(); }
  SallocLaunch(const SallocLaunch&) = delete;
  SallocLaunch& operator=(const SallocLaunch&) = delete;
  /// How it ended (waits for it: 60 s at most).
  const CommandResult& result() {
    if (thread_.joinable()) thread_.join();
    return result_;
  }
  const std::string appFile;

 private:
  CommandResult result_;
  std::thread thread_;
};

class Slurm : public ::testing::Test {
 protected:
  static void TearDownTestSuite() { slurm_.reset(); }
  void SetUp() override {
    if (const std::string why = whyNoSlurm(); !why.empty()) GTEST_SKIP() << why;
    useOwnHome();
    if (!slurm_) {
      slurm_ = std::make_unique<LocalSlurm>();
      ASSERT_EQ(slurm_->waitUntilIdle(), "");
    }
  }
  static std::unique_ptr<LocalSlurm> slurm_;
};
std::unique_ptr<LocalSlurm> Slurm::slurm_;

TEST_F(Slurm, TheSampleSbatchScriptGivesTheSameDigestsAsARunOnOneHost) {
  TempDir dir;
  const auto one = runVrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "-n", "100",
                              "--no-progress", "--report", dir.file("one.json")},
                             120);
  ASSERT_EQ(one.exitCode, 0) << one.err;
  // The script runs `vrflow` from PATH, in the folder it was submitted from, which holds
  // examples/ (here a link to the sources', so that what the run writes stays in `dir`).
  ASSERT_EQ(symlink((sourceDir() + "/examples").c_str(), dir.file("examples").c_str()), 0);
  const std::string path = binDir() + ":" + std::getenv("PATH");
  const auto job = runCommand(
      {"/usr/bin/sbatch", "--wait", "--chdir=" + dir.path(), "--output=" + dir.file("job.out"),
       "--export=ALL,PATH=" + path +
           ",VRFLOW_ITERATIONS=100,VRFLOW_REPORT=" + dir.file("three.json"),
       sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.sbatch"},
      60);
  ASSERT_EQ(job.exitCode, 0) << job.err << "\njob output:\n" << readFile(dir.file("job.out"));
  EXPECT_EQ(deterministicPart(dir.file("one.json")), deterministicPart(dir.file("three.json")));
  EXPECT_EQ(slurm_->steps(), "");
}

TEST_F(Slurm, ADaemonKilledUnderSlurmIsNamedTheRunFailsAndNothingIsLeft) {
  TempDir dir;
  SallocLaunch launch(dir, 3, {"-n", "0"});
  const DaemonSeen b = findDaemon(launch.appFile, "b");
  EXPECT_GT(b.pid, 0) << "no daemon of host b appeared";
  // Host b on node n2, listening on n2's address.
  EXPECT_NE(b.commandLine.find("--bind 127.0.0.2 "), std::string::npos) << b.commandLine;
  EXPECT_NE(b.environment.find("\nSLURMD_NODENAME=n2\n"), std::string::npos);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let the run get going
  if (b.pid > 0) kill(b.pid, SIGKILL);
  const CommandResult& result = launch.result();
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("vrflow: daemon of host 'b' (127.0.0.2, srun pid "), std::string::npos)
      << result.err;
  EXPECT_FALSE(daemonOfFileRuns(launch.appFile));
  EXPECT_EQ(slurm_->steps(), "");
}

TEST_F(Slurm, AKilledSrunIsNamedAndItsStepIsCancelled) {
  TempDir dir;
  SallocLaunch launch(dir, 3, {"-n", "0"});
  // Killed, srun leaves its step (and host b's daemon) running: the launcher cancels it.
  const DaemonSeen srun = findDaemon(launch.appFile, "b", "srun");
  EXPECT_GT(srun.pid, 0) << "no srun of host b appeared";
  EXPECT_GT(findDaemon(launch.appFile, "b").pid, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let the run get going
  if (srun.pid > 0) kill(srun.pid, SIGKILL);
  const CommandResult& result = launch.result();
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("vrflow: daemon of host 'b' (127.0.0.2, srun pid " +
                            std::to_string(srun.pid) + ") was killed by signal 9"),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("vrflow: cancelling slurm step "), std::string::npos) << result.err;
  EXPECT_FALSE(daemonOfFileRuns(launch.appFile));
  EXPECT_EQ(slurm_->steps(), "");
}

TEST_F(Slurm, MoreHostsThanNodesShareNodesAndAHostfilePlacesAHostOnANamedNode) {
  TempDir dir;
  const std::string hosts = dir.write("hosts", "# a on the second node\na node=n2\n");
  // Two nodes for three hosts: a on n2 (node=), b on n2 and c on n1 (host i on node i mod 2).
  SallocLaunch launch(dir, 2, {"--hosts", hosts, "-n", "0", "--timeout", "6"});
  const DaemonSeen a = findDaemon(launch.appFile, "a");
  const DaemonSeen b = findDaemon(launch.appFile, "b");
  const DaemonSeen c = findDaemon(launch.appFile, "c");
  const CommandResult& result = launch.result();
  EXPECT_EQ(result.exitCode, 3) << result.err;  // --timeout: the run went on until then
  EXPECT_NE(result.err.find("vrflow: 3 hosts on the 2 node(s) of slurm job "), std::string::npos)
      << result.err;
  EXPECT_NE(a.environment.find("\nSLURMD_NODENAME=n2\n"), std::string::npos);
  EXPECT_NE(a.commandLine.find("--bind 127.0.0.2 "), std::string::npos) << a.commandLine;
  EXPECT_NE(b.environment.find("\nSLURMD_NODENAME=n2\n"), std::string::npos);
  EXPECT_NE(c.environment.find("\nSLURMD_NODENAME=n1\n"), std::string::npos);
  EXPECT_NE(c.commandLine.find("--bind 127.0.0.1 "), std::string::npos) << c.commandLine;
  EXPECT_FALSE(daemonOfFileRuns(launch.appFile));
  EXPECT_EQ(slurm_->steps(), "");
}

TEST_F(Slurm, AHostfileNodeOutsideTheAllocationIsNamedWithItsLineAndNothingStarts) {
  TempDir dir;
  const std::string hosts = dir.write("hosts", "a\nb node=n9\n");
  const auto result =
      runCommand({"/usr/bin/salloc", "--nodes=2", "--time=2", binDir() + "/vrflow", "launch",
                  threeHostsFile(), "--backend", "slurm", "--hosts", hosts, "-n", "5"},
                 60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find(hosts + ":2: error: node 'n9' of host 'b' is not in slurm job "),
            std::string::npos)
      << result.err;
  EXPECT_EQ(slurm_->steps(), "");
}

TEST(SlurmBackend, OutsideAnAllocationIsOneClearErrorAndStartsNothing) {
  useOwnHome();
  for (const char* name : {"SLURM_JOB_ID", "SLURM_JOB_NODELIST", "SLURM_JOBID"}) unsetenv(name);
  const auto result = runVrflow({"launch", threeHostsFile(), "--backend", "slurm", "-n", "5"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find("--backend slurm runs inside a Slurm allocation (salloc or sbatch): "
                            "SLURM_JOB_ID is not set"),
            std::string::npos)
      << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
