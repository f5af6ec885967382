// What the supervisor of `vrflow run` tells about modules that stop answering or run out of
// memory: real processes, real signals, real limits.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string application(const std::string& modules, const std::string& connections) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"test\" version=\"1\">\n"
         "  <hosts>\n    <host id=\"h1\" address=\"127.0.0.1\"/>\n  </hosts>\n  <modules>\n" +
         modules + "  </modules>\n  <connections>\n" + connections +
         "  </connections>\n</application>\n";
}

std::string module(const std::string& id, const std::string& type, const std::string& params = "") {
  const auto slash = type.find('/');
  return "    <module id=\"" + id + "\" package=\"" + type.substr(0, slash) + "\" type=\"" +
         type.substr(slash + 1) + "\" host=\"h1\">\n" + params + "    </module>\n";
}

std::string param(const std::string& name, const std::string& value) {
  return "      <param name=\"" + name + "\" value=\"" + value + "\"/>\n";
}

std::string connect(const std::string& from, const std::string& to) {
  return "    <connection from=\"" + from + "\" to=\"" + to + "\"/>\n";
}

// A process named `name` (comm) started by a command this test runs, or 0.
pid_t grandchildNamed(const std::string& name) {
  const auto table = processTable();
  for (const auto& p : table) {
    if (p.name != name || p.state == 'Z') continue;
    for (const auto& parent : table) {
      if (parent.pid == p.parent && parent.parent == getpid()) return p.pid;
    }
  }
  return 0;
}

class SuperviseTest : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  // Runs `args` while, once the process `victim` runs, it is sent SIGSTOP.
  CommandResult runAndStop(const std::vector<std::string>& args, const std::string& victim) {
    CommandResult result;
    std::thread run([&] { result = runVrflow(args, 90); });
    pid_t stopped = 0;
    for (int i = 0; i < 200 && stopped == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      stopped = grandchildNamed(victim);
    }
    EXPECT_NE(stopped, 0) << "no process " << victim;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let the run get going
    if (stopped != 0) kill(stopped, SIGSTOP);
    run.join();
    return result;
  }
  TempDir dir;
};

TEST_F(SuperviseTest, AStoppedModuleIsNamedAsNotRespondingNotCalledADeadlock) {
  const auto file = dir.write(
      "app.xml", application(module("src", "core/source") + module("mid", "core/relay") +
                                 module("rec", "core/recorder", param("file", dir.file("x.csv"))),
                             connect("src.out", "mid.in") + connect("mid.out", "rec.in")));
  const auto report = dir.file("report.json");
  const auto result =
      runAndStop({"run", file, "--deadlock-timeout", "1", "--report", report}, "vrflow-core-rel");
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("stalled: no module progressed for 1 s: module 'mid' (host h1, pid "),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("is not responding: it is stopped (process state T"), std::string::npos)
      << result.err;
  EXPECT_EQ(result.err.find("deadlock"), std::string::npos) << result.err;
  EXPECT_EQ(nlohmann::json::parse(readFile(report))["status"], "stalled");
}

TEST_F(SuperviseTest, AModuleStoppedWhileItExitsIsNoStallButOneThatLingers) {
  // `mid` ends with the run and stops itself before it exits (as ASan's leak check holds an
  // exiting process under its tracer, state t): its slot says finished, so the run is not
  // called stalled; it ends as a module that finished but did not exit, stopped by the run.
  const auto file = dir.write(
      "app.xml", application(module("src", "core/source") +
                                 module("mid", "testing/slow", param("stop-at-exit", "true")) +
                                 module("rec", "core/recorder", param("file", dir.file("x.csv"))),
                             connect("src.out", "mid.in") + connect("mid.out", "rec.in")));
  const auto result = runVrflow({"run", file, "-n", "5", "--deadlock-timeout", "1"}, 90);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(result.err.find("stalled"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("module(s) 'mid' finished but did not exit; stopping them"),
            std::string::npos)
      << result.err;
}

TEST_F(SuperviseTest, ATrueDeadlockIsStillCalledOne) {
  // mute receives but never sends: the cycle through it blocks every module in wait().
  const auto file = dir.write(
      "app.xml", application(module("anim", "core/points",
                                    "      <input port=\"events\" initial-messages=\"1\"/>\n") +
                                 module("m", "testing/mute"),
                             connect("anim.objects", "m.in") + connect("m.out", "anim.events")));
  const auto result = runVrflow({"run", file, "--deadlock-timeout", "1"}, 60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("deadlock: no module progressed for 1 s and every module is blocked"),
            std::string::npos)
      << result.err;
  EXPECT_EQ(result.err.find("not responding"), std::string::npos) << result.err;
}

TEST_F(SuperviseTest, ExhaustedSharedMemoryIsNamedAsTheCause) {
  // 1500 points in a 1 MiB segment: the modules' messages fit, but not the daemon's merge of
  // the two force messages into chain.events; the filter drops it and every module waits.
  const auto result =
      runVrflow({"run", sourceDir() + "/examples/pipeline/pipeline.xml", "--set",
                 "chain.count=1500", "--set", "recorder.file=" + dir.file("x.csv"), "--shm-size",
                 "1", "--deadlock-timeout", "1", "-n", "300", "--no-progress"},
                60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("shared memory exhausted: "), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("failed in the 1 MiB segment"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("deadlock"), std::string::npos) << result.err;
}

TEST_F(SuperviseTest, AModuleOverTheMemoryLimitIsReportedWithTheLimitAsTheCause) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory counts against RLIMIT_DATA: no sanitized module "
                  "starts under a memory limit";
#endif
  // hog holds 16 MiB more each iteration (at most 512 MiB, should the limit not hold).
  const auto file = dir.write(
      "app.xml", application(module("hog", "testing/hog", param("max-mib", "512")) +
                                 module("rec", "core/recorder", param("file", dir.file("x.csv"))),
                             connect("hog.out", "rec.in")));
  const auto report = dir.file("report.json");
  const auto result =
      runVrflow({"run", file, "--module-memory-limit", "96M", "--report", report, "-n", "200"}, 60);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  const std::string cause =
      "ran out of memory under the module memory limit of 96 MiB (--module-memory-limit)";
  EXPECT_NE(result.err.find("module 'hog' (host h1, pid "), std::string::npos) << result.err;
  EXPECT_NE(result.err.find(cause), std::string::npos) << result.err;
  const auto json = nlohmann::json::parse(readFile(report));
  EXPECT_EQ(json["status"], "failed");
  ASSERT_EQ(json["modules"][0]["id"], "hog");
  EXPECT_NE(json["modules"][0].value("cause", "").find(cause), std::string::npos)
      << json["modules"][0];
  EXPECT_EQ(json["modules"][1].value("cause", ""), "");  // the recorder ended normally
}

TEST_F(SuperviseTest, AModuleUnderTheMemoryLimitRunsAsWithout) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory counts against RLIMIT_DATA: no sanitized module "
                  "starts under a memory limit";
#endif
  const auto file = dir.write(
      "app.xml", application(module("hog", "testing/hog", param("max-mib", "32")) +
                                 module("rec", "core/recorder", param("file", dir.file("x.csv"))),
                             connect("hog.out", "rec.in")));
  const auto result = runVrflow({"run", file, "--module-memory-limit", "1G", "-n", "10"}, 60);
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readLines(dir.file("x.csv")).size(), 11u);
}

}  // namespace
}  // namespace vrflow::testing
