// The monitor folder of `vrflow launch` / `vrflow monitor`: a folder that is not private to the
// user is refused, links planted in it are never followed, and the files of launchers killed
// with SIGKILL are removed.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string threeHostsFile() {
  return sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
}

// XDG_RUNTIME_DIR set to a folder of this test's own, so its monitor folder is <tmp>/vrflow.
class MonitorFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const char* previous = std::getenv("XDG_RUNTIME_DIR")) saved_ = previous;
    setenv("XDG_RUNTIME_DIR", dir.path().c_str(), 1);
  }
  void TearDown() override {
    if (saved_) {
      setenv("XDG_RUNTIME_DIR", saved_->c_str(), 1);
    } else {
      unsetenv("XDG_RUNTIME_DIR");
    }
    // A killed launcher's daemons die with it and come back to this test (a subreaper) to reap.
    for (const auto& left : leftoverProcesses()) {
      EXPECT_NE(left.find("(reaped)"), std::string::npos) << "still running: " << left;
    }
  }
  std::string folder() const { return dir.file("vrflow"); }
  TempDir dir;

 private:
  std::optional<std::string> saved_;
};

// The pid of a process that has ended (and was reaped).
pid_t deadPid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, nullptr, 0);
  return pid;
}

TEST_F(MonitorFolderTest, AFolderOthersMayWriteIsRefusedByMonitorAndLaunch) {
  ASSERT_EQ(mkdir(folder().c_str(), 0700), 0);
  ASSERT_EQ(chmod(folder().c_str(), 0777), 0);
  const auto shown = runVrflow({"monitor", "--once"}, 30);
  EXPECT_EQ(shown.exitCode, 1);
  EXPECT_NE(shown.err.find("'" + folder() + "' may be written by others (mode 0777)"),
            std::string::npos)
      << shown.err;
  const auto launched = runVrflow({"launch", threeHostsFile(), "-n", "20"}, 120);
  EXPECT_EQ(launched.exitCode, 0) << launched.err;
  EXPECT_NE(launched.err.find("`vrflow monitor` will not show this launch"), std::string::npos)
      << launched.err;
  EXPECT_EQ(runCommand({"/bin/sh", "-c", "ls -A '" + folder() + "'"}).out, "")
      << "the launch wrote into a folder that others may write";
}

TEST_F(MonitorFolderTest, AFolderOfAnotherUserIsRefused) {
  ASSERT_EQ(mkdir(folder().c_str(), 0700), 0);
  const uid_t other = getuid() == 0 ? 65534 : 0;
  if (chown(folder().c_str(), other, static_cast<gid_t>(-1)) != 0) {
    GTEST_SKIP() << "cannot give a folder to another user here";
  }
  const auto shown = runVrflow({"monitor", "--once"}, 30);
  EXPECT_EQ(shown.exitCode, 1);
  EXPECT_NE(shown.err.find("belongs to uid " + std::to_string(other) + ", not to you"),
            std::string::npos)
      << shown.err;
}

TEST_F(MonitorFolderTest, LinksPlantedUnderTheLaunchersNamesAreNeverFollowed) {
  ASSERT_EQ(mkdir(folder().c_str(), 0700), 0);
  const auto victim = dir.write("victim.txt", "precious\n");
  const auto victimTmp = dir.write("victim-tmp.txt", "precious too\n");
  // The shell's pid is the launcher's (exec): links under both names the launcher writes.
  const auto result =
      runCommand({"/bin/sh", "-c",
                  "ln -s '" + victim + "' '" + folder() + "'/monitor-$$.json && ln -s '" +
                      victimTmp + "' '" + folder() + "'/monitor-$$.json.tmp && exec '" + binDir() +
                      "/vrflow' launch '" + threeHostsFile() + "' -n 20"},
                 120);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readFile(victim), "precious\n");
  EXPECT_EQ(readFile(victimTmp), "precious too\n");
  // The launcher has ended: what it left (the planted temporary link) goes at the next look.
  runVrflow({"monitor", "--once"}, 30);
  EXPECT_EQ(runCommand({"/bin/sh", "-c", "ls -A '" + folder() + "'"}).out, "");
}

TEST_F(MonitorFolderTest, TheFileOfALauncherKilledWithSigkillIsRemovedAtTheNextLook) {
  // A launcher killed with SIGKILL cannot remove its file.
  const auto killed = runVrflow({"launch", threeHostsFile(), "--timeout", "60"}, 90, 3, SIGKILL);
  EXPECT_EQ(killed.exitCode, 128 + SIGKILL);
  const auto left = runCommand({"/bin/sh", "-c", "ls -A '" + folder() + "'"}).out;
  EXPECT_NE(left.find("monitor-"), std::string::npos) << "the launch published nothing";
  // And one of a launcher long gone, with a temporary of it.
  const pid_t dead = deadPid();
  dir.write("vrflow/monitor-" + std::to_string(dead) + ".json", "{\"hosts\":[]}");
  dir.write("vrflow/monitor-" + std::to_string(dead) + ".json.Ab12Cd", "{");
  const auto shown = runVrflow({"monitor", "--once"}, 30);
  EXPECT_EQ(shown.exitCode, 1);
  EXPECT_NE(shown.err.find("no launch is running"), std::string::npos) << shown.err;
  EXPECT_EQ(runCommand({"/bin/sh", "-c", "ls -A '" + folder() + "'"}).out, "");
}

}  // namespace
}  // namespace vrflow::testing
