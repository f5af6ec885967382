// `vrflow launch` refuses what it cannot honour before any daemon starts, and documents itself.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <regex>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string threeHostsText() {
  return readFile(sourceDir() + "/examples/pipeline_3hosts/pipeline_3hosts.xml");
}

class LaunchCommandLineTest : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

// Item 9: the report's folder was found missing only after the whole run.
TEST_F(LaunchCommandLineTest, ReportOrTracePathThatCannotBeWrittenIsRefusedBeforeAnyDaemon) {
  // The recorder writes out/demo-3hosts/trajectory.csv relative to the working folder: here.
  const std::string app = dir.write("app.xml", threeHostsText());
  const std::string csv = dir.file("out/demo-3hosts/trajectory.csv");
  for (const std::vector<std::string>& output :
       {std::vector<std::string>{"--report", dir.file("missing/r.json")},
        std::vector<std::string>{"--trace", dir.path()}}) {
    std::string command = "cd '" + dir.path() + "' && exec '" + binDir() + "/vrflow' launch '" +
                          app + "' --backend local -n 1000 '" + output[0] + "' '" + output[1] + "'";
    const auto begin = std::chrono::steady_clock::now();
    const auto result = runCommand({"/bin/sh", "-c", command});
    EXPECT_EQ(result.exitCode, 2) << result.err;
    EXPECT_TRUE(
        std::regex_search(result.err, std::regex("^vrflow: cannot write the (report|trace) to '")))
        << result.err;
    EXPECT_FALSE(std::filesystem::exists(csv)) << "a daemon started its modules";
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(),
              10.0);
  }
}

// Item 12: `address="999.1.1.1"` passed validate and ran under `launch --backend local`.
TEST_F(LaunchCommandLineTest, InvalidHostAddressIsRefusedBeforeAnyDaemon) {
  std::string text = threeHostsText();
  text.replace(text.find("127.0.0.2"), 9, "999.1.1.1");
  const std::string app = dir.write("app.xml", text);
  const auto result = runVrflow({"launch", app, "--backend", "local", "-n", "5"});
  EXPECT_EQ(result.exitCode, 2);
  EXPECT_NE(result.err.find(app + ":5:18: error: address '999.1.1.1' of host 'b' is not a "
                                  "valid IPv4 address"),
            std::string::npos)
      << result.err;
}

// Item 12: `launch --help` pointed to docs/launcher.md, which did not exist.
TEST_F(LaunchCommandLineTest, HelpListsEveryOptionAndItsReferenceExists) {
  const auto help = runCommand({binDir() + "/vrflow", "launch", "--help"});
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("docs/launcher.md"), std::string::npos) << help.out;
  const std::string reference = readFile(sourceDir() + "/docs/launcher.md");
  for (const char* option :
       {"--hosts", "--backend", "--iterations", "--report", "--trace", "--events", "--timeout",
        "--peer-timeout", "--control-address", "--packages", "--composites", "--set"}) {
    EXPECT_NE(help.out.find(option), std::string::npos) << "launch --help lacks " << option;
    EXPECT_NE(reference.find(std::string("`") + option), std::string::npos)
        << "docs/launcher.md lacks " << option;
  }
  for (const char* key :
       {"address=", "user=", "ssh-port=", "identity=", "ssh-option=", "dir=", "daemon=", "env="}) {
    EXPECT_NE(reference.find(key), std::string::npos) << "docs/launcher.md lacks " << key;
  }
}

}  // namespace
}  // namespace vrflow::testing
