// Supervision under `vrflow launch`: a module stopped (SIGSTOP) is named by the host that runs
// it, with its state (the hosts that wait on it do not call the run a deadlock of theirs); a
// module over --module-memory-limit is named with its host and the limit.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

// A process named `name` (comm) below this test, or 0.
pid_t descendantNamed(const std::string& name) {
  const auto table = processTable();
  auto parentOf = [&](pid_t pid) {
    for (const auto& p : table) {
      if (p.pid == pid) return p.parent;
    }
    return pid_t{0};
  };
  for (const auto& p : table) {
    if (p.name != name || p.state == 'Z') continue;
    for (pid_t up = p.parent, hops = 0; up > 1 && hops < 6; up = parentOf(up), ++hops) {
      if (up == getpid()) return p.pid;
    }
  }
  return 0;
}

TEST(LaunchStall, AStoppedModuleIsNamedWithItsHostNotBlamedOnAnotherHost) {
  const std::string file = sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml";
  CommandResult result;
  std::thread launch([&] { result = runVrflow({"launch", file, "--timeout", "60"}, 90); });
  pid_t springs = 0;
  for (int i = 0; i < 300 && springs == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    springs = descendantNamed("vrflow-core-spr");  // comm keeps 15 characters
  }
  EXPECT_NE(springs, 0) << "no springs module";
  // Stop it only once the network iterates (a module stopped before it joined its daemon is a
  // start failure, not a stall): this launch's entry in `vrflow list` counts iterations. A
  // sanitized module on a loaded machine takes seconds to get there.
  const pid_t launcher = descendantNamed("vrflow");
  uint64_t iterations = 0;
  for (int i = 0; i < 120 && launcher != 0 && iterations < 20; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    const auto listed = runVrflow({"list", "--json"}, 20);
    const auto runs = nlohmann::json::parse(listed.out, nullptr, false);
    if (!runs.is_array()) continue;
    for (const auto& run : runs) {
      if (run.value("pid", 0) == launcher) iterations = run.value("iterations", uint64_t{0});
    }
  }
  EXPECT_GE(iterations, 20u) << "the launch (pid " << launcher << ") did not get going";
  if (springs != 0) kill(springs, SIGSTOP);
  launch.join();
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("host 'b': stalled: no module progressed for 10 s: module 'springs' "
                            "(host b, pid " +
                            std::to_string(springs) +
                            ") is not responding: it is stopped (process state T"),
            std::string::npos)
      << result.err;
  EXPECT_EQ(result.err.find("deadlock"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("initial messages only"), std::string::npos) << result.err;
  for (const auto& left : leftoverProcesses()) {
    EXPECT_NE(left.find("(reaped)"), std::string::npos) << "still running: " << left;
  }
}

TEST(LaunchMemoryLimit, AModuleOverTheLimitIsNamedWithItsHostAndTheLimit) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's shadow memory counts against RLIMIT_DATA: no sanitized module "
                  "starts under a memory limit";
#endif
  TempDir dir;
  const auto file = dir.write(
      "app.xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"hog\" version=\"1\">\n"
      "  <hosts>\n    <host id=\"a\" address=\"127.0.0.1\"/>\n"
      "    <host id=\"b\" address=\"127.0.0.2\"/>\n  </hosts>\n  <modules>\n"
      "    <module id=\"hog\" package=\"testing\" type=\"hog\" host=\"b\">\n"
      "      <param name=\"max-mib\" value=\"512\"/>\n    </module>\n"
      "    <module id=\"rec\" package=\"core\" type=\"recorder\" host=\"a\">\n"
      "      <param name=\"file\" value=\"" +
          dir.file("x.csv") +
          "\"/>\n    </module>\n  </modules>\n  <connections>\n"
          "    <connection from=\"hog.out\" to=\"rec.in\"/>\n  </connections>\n</application>\n");
  const auto result = runVrflow(
      {"launch", file, "--module-memory-limit", "96M", "-n", "200", "--timeout", "60"}, 90);
  EXPECT_EQ(result.exitCode, 1) << result.err;
  EXPECT_NE(result.err.find("host 'b': module 'hog' (host b, pid "), std::string::npos)
      << result.err;
  EXPECT_NE(result.err.find("ran out of memory under the module memory limit of 96 MiB "
                            "(--module-memory-limit)"),
            std::string::npos)
      << result.err;
  EXPECT_TRUE(leftoverProcesses().empty());
}

}  // namespace
}  // namespace vrflow::testing
