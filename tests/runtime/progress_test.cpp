// The progress of `vrflow run` (issue 19, item 7): a live line on a terminal, one summary line
// at the end otherwise.
#include "vrflow/run/progress.hpp"

#include <gtest/gtest.h>

#include <regex>

#include "formats_support.hpp"

namespace vrflow::testing {
namespace {

// A shell word for a command line of `script -c`.
std::string quoted(const std::string& word) {
  return "'" + word + "'";
}

TEST(Progress, OuterIterationsAreTheLeastShareOfAnyModulesTarget) {
  using run::ModuleProgress;
  // -n 10: a module behind a repeat of 3 runs 30; 15 of them are 5 outer iterations.
  EXPECT_EQ(run::outerIterationsDone({{10, 10}, {15, 30}}, 10), 5u);
  EXPECT_EQ(run::outerIterationsDone({{10, 10}, {30, 30}}, 10), 10u);
  EXPECT_EQ(run::outerIterationsDone({{12, 10}}, 10), 10u) << "never past -n";
  EXPECT_EQ(run::outerIterationsDone({{7, 0}, {9, 0}}, 0), 7u) << "without -n: the fewest";
  EXPECT_EQ(run::outerIterationsDone({}, 10), 0u);
}

TEST(Progress, NotOnATerminalARunEndsWithOneSummaryLine) {
  TempDir dir;
  const auto result = runVrflow({"run", relayPipeline(dir), "-n", "40"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(result.err.find('\r'), std::string::npos) << "no live line: " << result.err;
  const std::regex summary(
      "vrflow: 40 of 40 iterations in [0-9]+\\.[0-9] s \\([0-9]+\\.[0-9] it/s\\), status ok\n");
  EXPECT_TRUE(std::regex_search(result.err, summary)) << result.err;

  const auto quiet = runVrflow({"run", relayPipeline(dir), "-n", "40", "--no-progress"});
  ASSERT_EQ(quiet.exitCode, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("iterations in"), std::string::npos) << quiet.err;
}

TEST(Progress, TheSummaryLineNamesAFailedRunsStatus) {
  TempDir dir;
  const auto result =
      runVrflow({"run", relayPipeline(dir, "core/relay", paramXml("delay-ms", "10")), "-n",
                 "100000", "--timeout", "1.5"},
                60);
  ASSERT_EQ(result.exitCode, 3) << result.err;
  const std::regex summary(
      "vrflow: [0-9]+ of 100000 iterations in [0-9.]+ s \\([0-9.]+ it/s\\), status timeout\n");
  EXPECT_TRUE(std::regex_search(result.err, summary)) << result.err;
}

TEST(Progress, OnATerminalALiveLineShowsIterationsOfNRateAndTimeLeft) {
  TempDir dir;
  // `script` gives the command a pseudo-terminal and copies what it shows to stdout.
  const std::string command =
      quoted(binDir() + "/vrflow") + " --packages " + quoted(binDir() + "/../test-packages") +
      " run " + quoted(relayPipeline(dir, "core/relay", paramXml("delay-ms", "100"))) + " -n 30";
  const auto result = runCommand({"/usr/bin/script", "-qec", command, "/dev/null"}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.out << result.err;
  const std::regex live(
      "\r\\[vrflow [0-9]+s\\] [0-9]+/30 iterations \\([0-9]+%\\), [0-9.]+ it/s, ([0-9]+s|\\?) "
      "left\x1b\\[K");
  EXPECT_TRUE(std::regex_search(result.out, live)) << result.out;
  // The summary replaces the live line at the end.
  EXPECT_NE(result.out.find("\r\x1b[Kvrflow: 30 of 30 iterations in "), std::string::npos)
      << result.out;
}

}  // namespace
}  // namespace vrflow::testing
