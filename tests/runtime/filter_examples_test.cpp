// Every filter example in examples/ runs with the real `vrflow run`, from a temporary working
// directory (where the examples' relative output files land), and does what its README says.
#include <gtest/gtest.h>

#include <chrono>
#include <sstream>

#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

struct Row {  // one line of a core/recorder CSV for a resource chunk
  long recorderIteration = 0;
  std::string source;
  long counter = 0;
  long size = 0;
};

class FilterExamples : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
  }

  // `vrflow run SOURCE/examples/<example> <extra>` from the temporary directory.
  CommandResult runExample(const std::string& example, const std::string& extra = "",
                           double timeoutSeconds = 60) {
    return runCommand({"/bin/sh", "-c",
                       "cd " + dir.path() + " && " + binDir() + "/vrflow run " + sourceDir() +
                           "/examples/" + example + " " + extra},
                      timeoutSeconds);
  }

  // iteration,source,source_iteration,sim_time,kind,id,x,y,z; x: counter, y: payload size.
  std::vector<Row> readRows(const std::string& csv) {
    std::vector<Row> rows;
    const auto lines = readLines(dir.file(csv));
    for (std::size_t i = 1; i < lines.size(); ++i) {
      std::vector<std::string> f;
      std::stringstream in(lines[i]);
      for (std::string field; std::getline(in, field, ',');) f.push_back(field);
      EXPECT_GE(f.size(), 8u) << lines[i];
      EXPECT_EQ(f.size() >= 5 ? f[4] : "", "resource") << lines[i];
      if (f.size() < 8) continue;
      rows.push_back({std::stol(f[0]), f[1], std::stol(f[6]), std::stol(f[7])});
    }
    return rows;
  }

  std::vector<long> counters(const std::string& csv) {
    std::vector<long> result;
    for (const auto& row : readRows(csv)) result.push_back(row.counter);
    return result;
  }

  TempDir dir;
};

// merge: one chunk of each producer per message, both of the same iteration, left then right.
TEST_F(FilterExamples, MergeTwoProducersPairsEqualCounters) {
  const auto result = runExample("merge_two_producers/merge_two_producers.xml");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto rows = readRows("merged.csv");
  ASSERT_EQ(rows.size(), 40u);
  for (std::size_t i = 0; i < rows.size(); i += 2) {
    const long iteration = static_cast<long>(i / 2);
    EXPECT_EQ(rows[i].recorderIteration, iteration);
    EXPECT_EQ(rows[i + 1].recorderIteration, iteration) << "both chunks in one message";
    EXPECT_EQ(rows[i].counter, iteration);
    EXPECT_EQ(rows[i + 1].counter, iteration) << "the same counter from both producers";
    EXPECT_EQ(rows[i].size, 16) << "left's chunk first";
    EXPECT_EQ(rows[i + 1].size, 32) << "right's chunk second";
  }
}

// gate: the control stream alternates close/open in lockstep with the data: odd ones pass.
TEST_F(FilterExamples, GatedStreamPassesOnlyWhileOpen) {
  const auto result = runExample("gated_stream/gated_stream.xml");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(counters("gated.csv"), (std::vector<long>{1, 3, 5, 7, 9, 11, 13, 15, 17, 19}));
}

// rotate/unrotate: workers of different speeds, results in the input order.
TEST_F(FilterExamples, RotateWorkersKeepInputOrder) {
  const auto result = runExample("rotate_workers/rotate_workers.xml");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::vector<long> expected(30);
  for (long i = 0; i < 30; ++i) expected[static_cast<std::size_t>(i)] = i;
  EXPECT_EQ(counters("rotated.csv"), expected);
}

// latest + maxfrequency: increasing samples, far fewer than produced, at most the cap's rate,
// the newest last.
TEST_F(FilterExamples, GreedySamplingSeesIncreasingNewestSamples) {
  const auto start = std::chrono::steady_clock::now();
  const auto result = runExample("greedy_sampling/greedy_sampling.xml");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto seen = counters("sampled.csv");
  ASSERT_GE(seen.size(), 2u);
  for (std::size_t i = 1; i < seen.size(); ++i) {
    ASSERT_LT(seen[i - 1], seen[i]) << "samples increase (row " << i << ")";
  }
  EXPECT_LT(seen.size(), 200000u / 10) << "the reader skipped most messages";
  EXPECT_LE(static_cast<double>(seen.size()), 50.0 * seconds + 2) << "capped at 50 per second";
  EXPECT_EQ(seen.back(), 199999) << "the newest message is seen last";
}

// endIt -> initial(3) -> beginIt: the producer is never more than 3 iterations ahead.
TEST_F(FilterExamples, PacedProducerStaysAtMostNAhead) {
  const auto result = runExample("paced_producer/paced_producer.xml", "-n 300");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  int produced = 0, consumed = 0, worst = 0;
  for (const auto& line : readLines(dir.file("paced.log"))) {
    if (line.rfind("producer ", 0) == 0) ++produced;
    if (line.rfind("consumer ", 0) == 0) ++consumed;
    worst = std::max(worst, produced - consumed);
  }
  EXPECT_EQ(produced, 300);
  EXPECT_EQ(consumed, 300);
  EXPECT_LE(worst, 3) << "the producer ran more than 3 iterations ahead";
  EXPECT_GE(worst, 1) << "the producer is allowed ahead at all";
}

}  // namespace
}  // namespace vrflow::testing
