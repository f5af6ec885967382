// vrflow-daemon under `--control`, stopped before the launcher's "go": by the end of its control
// input, by "stop", and by a link that fails while the hosts connect. Each must end with a
// clean exit status, one line saying why, its report to the launcher, and nothing left behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

struct DaemonRun {
  int exitCode = -1;         ///< exit status, or 128 + signal
  std::string control, err;  ///< what it said to the launcher, and on stderr
};

// Starts host a's daemon of the three-host pipeline under --control, writes `lines` on its
// control input, then closes that input (at once, or after `holdSeconds` when > 0). Killed after
// 30 s if it has not ended.
DaemonRun runDaemon(const std::string& lines, double holdSeconds = 0) {
  TempDir dir;
  const std::string outFile = dir.file("out.txt"), errFile = dir.file("err.txt");
  int in[2];
  EXPECT_EQ(pipe2(in, O_CLOEXEC), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(in[0], 0);
    const int out = open(outFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int err = open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(out, 1);
    dup2(err, 2);
    const std::string daemon = binDir() + "/vrflow-daemon";
    const std::string app = sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
    execl(daemon.c_str(), daemon.c_str(), app.c_str(), "--host", "a", "--control", "--bind",
          "127.0.0.1", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(in[0]);
  const std::string text = "secret " + std::string(63, '0') + "1\n" + lines;
  EXPECT_EQ(write(in[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  if (holdSeconds > 0) std::this_thread::sleep_for(std::chrono::duration<double>(holdSeconds));
  close(in[1]);
  DaemonRun run;
  int status = 0;
  for (int i = 0; i < 300 && run.exitCode < 0; ++i) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  if (run.exitCode < 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  run.control = readFile(outFile);
  run.err = readFile(errFile);
  return run;
}

// The line of `control` that starts with `word` and a space, without them; empty if none.
std::string controlLine(const std::string& control, const std::string& word) {
  std::istringstream lines(control);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(word + " ", 0) == 0) return line.substr(word.size() + 1);
  }
  return {};
}

// What every stop before "go" must show: status 1 (not a crash), `why` on stderr, a report of
// modules that did not start, and nothing left.
void expectCleanStop(const DaemonRun& run, const std::string& why,
                     const std::vector<std::string>& shmBefore) {
  EXPECT_EQ(run.exitCode, 1) << run.err;
  EXPECT_NE(run.err.find("vrflow-daemon (host a): " + why), std::string::npos) << run.err;
  EXPECT_NE(controlLine(run.control, "finished").find("failed"), std::string::npos) << run.control;
  const std::string report = controlLine(run.control, "report");
  ASSERT_FALSE(report.empty()) << run.control;
  const auto json = nlohmann::json::parse(report);
  EXPECT_EQ(json["status"], "failed");
  ASSERT_FALSE(json["modules"].empty());
  for (const auto& m : json["modules"]) EXPECT_EQ(m["exit"], "not started") << m;
  EXPECT_TRUE(leftoverProcesses().empty());
  EXPECT_EQ(vrflowShmEntries(), shmBefore);
}

TEST(DaemonStopBeforeGo, EndOfControlInputEndsItCleanly) {
  const auto shm = vrflowShmEntries();
  const auto run = runDaemon("");
  expectCleanStop(run, "the launcher closed the control channel before the start", shm);
}

TEST(DaemonStopBeforeGo, StopEndsItCleanly) {
  const auto shm = vrflowShmEntries();
  // The control input stays open: "stop" alone must end it.
  const auto run = runDaemon("stop\n", 3);
  expectCleanStop(run, "stopped by the launcher before the start", shm);
}

TEST(DaemonStopBeforeGo, ALinkThatFailsWhileHostsConnectEndsItCleanly) {
  const auto shm = vrflowShmEntries();
  // A port of 127.0.0.2 where nobody listens (bound, then closed): host b refuses the link.
  const std::string port = std::to_string(unusedPort("127.0.0.2"));
  ASSERT_NE(port, "0");
  const auto run =
      runDaemon("peer 1 127.0.0.2 " + port + "\npeer 2 127.0.0.3 " + port + "\nconnect\n");
  expectCleanStop(run, "cannot link to the other hosts: cannot reach host 'b'", shm);
  EXPECT_NE(controlLine(run.control, "error").find("cannot reach host 'b'"), std::string::npos)
      << run.control;
}

}  // namespace
}  // namespace vrflow::testing
