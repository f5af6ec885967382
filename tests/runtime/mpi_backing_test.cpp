// Open MPI's shared-memory files of an MPI job (vader segments) live in a folder the runtime
// owns: none is left in /dev/shm itself when the runtime is killed with SIGKILL, and the folder
// of a killed run is removed at the next start. Any run's start removes it, so these tests run
// alone (RUN_SERIAL): another test's `vrflow run` starting meanwhile cleared the folder before
// this test looked (the sanitizer suites, many runs on two cores, showed it).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// Two mpitest/rank modules of MPI job `water` (one mpirun -np 2), each with its recorder.
std::string twoRankJob(const TempDir& dir) {
  std::string modules, connections;
  for (const char* id : {"b0", "b1"}) {
    modules += "    <module id=\"" + std::string(id) +
               "\" package=\"mpitest\" type=\"rank\" host=\"local\">\n"
               "      <param name=\"job\" value=\"water\"/>\n    </module>\n"
               "    <module id=\"rec-" +
               id +
               "\" package=\"core\" type=\"recorder\" host=\"local\">\n"
               "      <param name=\"file\" value=\"" +
               dir.file(std::string(id) + ".csv") + "\"/>\n    </module>\n";
    connections +=
        "    <connection from=\"" + std::string(id) + ".out\" to=\"rec-" + id + ".in\"/>\n";
  }
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"jobs\" version=\"1\">\n"
         "  <hosts>\n    <host id=\"local\" address=\"127.0.0.1\"/>\n  </hosts>\n  <modules>\n" +
         modules + "  </modules>\n  <connections>\n" + connections +
         "  </connections>\n</application>\n";
}

// Names in /dev/shm that start with `prefix`.
std::set<std::string> shmNames(const std::string& prefix) {
  std::set<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev/shm", ec)) {
    const auto name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.insert(name);
  }
  return names;
}

// The ranks of a killed run die by their parent-death signal and come back to this test (a
// subreaper): waits until none runs, reaping them.
void reapOrphans(double seconds) {
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

// "ompi-job.PID.N": the folder of a run whose process is still alive (another test's run going on
// at the same time), which this test must not count.
bool ofALiveRun(const std::string& folder) {
  const long pid = std::strtol(folder.c_str() + std::strlen("ompi-job."), nullptr, 10);
  return pid > 0 && kill(static_cast<pid_t>(pid), 0) == 0;
}

TEST(MpiBackingFolder, KillingTheRunLeavesNoSegmentInDevShmAndTheNextStartRemovesItsFolder) {
  TempDir dir;
  const auto file = dir.write("jobs.xml", twoRankJob(dir));
  const auto segmentsBefore = shmNames("vader_segment");
  const auto foldersBefore = shmNames("ompi-job.");
  // An endless run, killed with SIGKILL once its ranks have joined and talk.
  const auto killed = runVrflow({"run", file, "--no-progress"}, 60, 5, SIGKILL);
  EXPECT_EQ(killed.exitCode, 128 + SIGKILL) << killed.err;
  reapOrphans(10);
  ASSERT_FALSE(readLines(dir.file("b0.csv")).empty()) << "the job never ran: " << killed.err;

  std::set<std::string> newSegments;
  for (const auto& name : shmNames("vader_segment")) {
    if (segmentsBefore.count(name) == 0) newSegments.insert(name);
  }
  EXPECT_TRUE(newSegments.empty()) << "Open MPI left " << *newSegments.begin() << " in /dev/shm";
  // The folder is named after a process of the killed run, which may take a moment more to die
  // (under ASan in particular): until then it looks like another test's live run.
  std::set<std::string> leftFolders;
  for (int tries = 0; tries < 100 && leftFolders.empty(); ++tries) {
    if (tries > 0) usleep(100000);
    for (const auto& name : shmNames("ompi-job.")) {
      if (foldersBefore.count(name) == 0 && !ofALiveRun(name)) leftFolders.insert(name);
    }
  }
  ASSERT_EQ(leftFolders.size(), 1u) << "the killed run's folder";
  const std::string left = "/dev/shm/" + *leftFolders.begin();
  bool segmentInside = false;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(left, ec)) {
    if (entry.path().filename().string().rfind("vader_segment", 0) == 0) segmentInside = true;
  }
  EXPECT_TRUE(segmentInside) << "the ranks' segments were not in " << left;

  // The next run removes the folder of the dead one, and its own at its end.
  const auto next = runVrflow({"run", file, "-n", "3", "--no-progress"}, 120);
  EXPECT_EQ(next.exitCode, 0) << next.err;
  reapOrphans(10);
  EXPECT_FALSE(std::filesystem::exists(left)) << left << " outlived the next start";
  for (const auto& name : shmNames("ompi-job.")) {
    if (ofALiveRun(name)) continue;
    EXPECT_NE(foldersBefore.count(name), 0u) << "left behind: /dev/shm/" << name;
  }
  for (const auto& name : shmNames("vader_segment")) {
    EXPECT_NE(segmentsBefore.count(name), 0u) << "left behind: /dev/shm/" << name;
  }
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
