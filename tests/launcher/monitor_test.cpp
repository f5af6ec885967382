// The runtime folder of the registry of runs (`vrflow launch` / `vrflow monitor`): a folder that
// is not private to the user is refused, a link planted in it is never followed, and the
// records of launchers killed with SIGKILL leave it.
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

// XDG_RUNTIME_DIR set to a folder of this test's own, so its runtime folder is <tmp>/vrflow
// (and XDG_STATE_HOME, for the ended runs).
class MonitorFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const char* previous = std::getenv("XDG_RUNTIME_DIR")) saved_ = previous;
    if (const char* previous = std::getenv("XDG_STATE_HOME")) savedState_ = previous;
    setenv("XDG_RUNTIME_DIR", dir.path().c_str(), 1);
    setenv("XDG_STATE_HOME", dir.file("state").c_str(), 1);
  }
  void TearDown() override {
    if (saved_) {
      setenv("XDG_RUNTIME_DIR", saved_->c_str(), 1);
    } else {
      unsetenv("XDG_RUNTIME_DIR");
    }
    if (savedState_) {
      setenv("XDG_STATE_HOME", savedState_->c_str(), 1);
    } else {
      unsetenv("XDG_STATE_HOME");
    }
    // A killed launcher's daemons die with it and come back to this test (a subreaper) to reap.
    for (const auto& left : leftoverProcesses()) {
      EXPECT_NE(left.find("(reaped)"), std::string::npos) << "still running: " << left;
    }
  }
  std::string folder() const { return dir.file("vrflow"); }
  TempDir dir;

 private:
  std::optional<std::string> saved_, savedState_;
};

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

TEST_F(MonitorFolderTest, ALinkPlantedAsTheRegistryIsNeverFollowed) {
  ASSERT_EQ(mkdir(folder().c_str(), 0700), 0);
  ASSERT_EQ(mkdir(dir.file("victim").c_str(), 0700), 0);
  ASSERT_EQ(symlink(dir.file("victim").c_str(), (folder() + "/runs").c_str()), 0);
  const auto launched = runVrflow({"launch", threeHostsFile(), "-n", "20"}, 120);
  EXPECT_EQ(launched.exitCode, 0) << launched.err;
  EXPECT_NE(launched.err.find("`vrflow monitor` will not show this launch"), std::string::npos)
      << launched.err;
  EXPECT_EQ(runCommand({"/bin/sh", "-c", "ls -A '" + dir.file("victim") + "'"}).out, "")
      << "the launch wrote through the link";
  const auto listed = runVrflow({"list"}, 30);
  EXPECT_EQ(listed.exitCode, 1);
  EXPECT_NE(listed.err.find("is not a folder of yours"), std::string::npos) << listed.err;
}

TEST_F(MonitorFolderTest, TheRecordOfALauncherKilledWithSigkillLeavesAtTheNextLook) {
  // A launcher killed with SIGKILL cannot move its record.
  const auto killed = runVrflow({"launch", threeHostsFile(), "--timeout", "60"}, 90, 3, SIGKILL);
  EXPECT_EQ(killed.exitCode, 128 + SIGKILL);
  const auto left = runCommand({"/bin/sh", "-c", "ls -A '" + folder() + "/runs'"}).out;
  EXPECT_NE(left.find("pipeline-"), std::string::npos) << "the launch registered nothing";
  const auto shown = runVrflow({"monitor", "--once"}, 30);
  EXPECT_EQ(shown.exitCode, 1);
  EXPECT_NE(shown.err.find("no run is running"), std::string::npos) << shown.err;
  EXPECT_EQ(runCommand({"/bin/sh", "-c", "ls -A '" + folder() + "/runs'"}).out, "");
  const auto all = runVrflow({"list", "--all"}, 30);
  EXPECT_NE(all.out.find("lost"), std::string::npos) << all.out;
}

}  // namespace
}  // namespace vrflow::testing
