// The opt-in spin before sleeping (VRFLOW_SPIN_US, docs/shared-memory.md): a run with it delivers
// the same messages as one without, and a bad value is refused before anything starts. Each
// test runs the real `vrflow`, which inherits this process's environment.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

class SpinTest : public ::testing::Test {
 protected:
  void TearDown() override {
    unsetenv("VRFLOW_SPIN_US");
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  // source -> relay -> recorder writing `csv`.
  std::string pipeline(const std::string& csv) {
    return dir.write("app.xml",
                     appXml(moduleXml("src", "core/source", paramXml("size", "256")) +
                                moduleXml("mid", "core/relay") +
                                moduleXml("rec", "core/recorder", paramXml("file", csv)),
                            "", connectXml("src.out", "mid.in") + connectXml("mid.out", "rec.in")));
  }
  TempDir dir;
};

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST_F(SpinTest, ARunThatSpinsDeliversTheSameMessagesAsOneThatSleeps) {
  const std::string sleeping = dir.file("sleeping.csv");
  const std::string spinning = dir.file("spinning.csv");
  auto result = runVrflow({"run", pipeline(sleeping), "--iterations", "200", "--no-progress"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  setenv("VRFLOW_SPIN_US", "50", 1);
  result = runVrflow({"run", pipeline(spinning), "--iterations", "200", "--no-progress"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const std::string recorded = fileText(sleeping);
  EXPECT_EQ(recordedCounters(spinning).size(), 200u);
  EXPECT_EQ(fileText(spinning), recorded);
}

TEST_F(SpinTest, ASpinThatIsNotAWholeNumberOfMicrosecondsUpToAMillisecondIsRefused) {
  const std::string csv = dir.file("out.csv");
  const std::string file = pipeline(csv);
  for (const char* bad : {"abc", "-5", "1001", "12us", "1.5"}) {
    setenv("VRFLOW_SPIN_US", bad, 1);
    const auto result = runVrflow({"run", file, "--iterations", "10", "--no-progress"});
    EXPECT_NE(result.exitCode, 0) << bad;
    EXPECT_NE(result.err.find("VRFLOW_SPIN_US='" + std::string(bad) +
                              "': expected a whole number of microseconds from 0 to 1000"),
              std::string::npos)
        << result.err;
    EXPECT_FALSE(std::filesystem::exists(csv)) << bad << ": the run started";
  }
}

}  // namespace
}  // namespace vrflow::testing
