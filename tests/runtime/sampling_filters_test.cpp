// End-to-end tests of the sampling and selecting filters (docs/filters.md): latest,
// maxfrequency, stampfilter, typefilter; and `vrflow validate` on all the standard filters.
#include <gtest/gtest.h>

#include <chrono>
#include <map>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

class SamplingFilters : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  // Runs the application; returns how long `vrflow run` took, in seconds.
  double run(const std::string& xml) {
    const auto start = std::chrono::steady_clock::now();
    const auto result = runVrflow({"run", dir.write("app.xml", xml), "--timeout", "60"});
    EXPECT_EQ(result.exitCode, 0) << result.err;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  std::string recorder(const std::string& id, const std::string& csv) {
    return moduleXml(id, "core/recorder", paramXml("file", dir.file(csv)));
  }
  TempDir dir;
};

std::string source(const std::string& id, int count) {
  return moduleXml(id, "core/source", paramXml("count", std::to_string(count)));
}

void expectIncreasing(const std::vector<long>& values) {
  for (std::size_t i = 1; i < values.size(); ++i) {
    EXPECT_LT(values[i - 1], values[i]) << "at " << i;
  }
}

// FlowVR's greedy pattern: the reader's endIt asks for the next sample; the writer never waits.
TEST_F(SamplingFilters, LatestGivesASlowReaderOnlyTheNewestMessageOnEachSync) {
  run(appXml(source("src", 2000) + moduleXml("reader", "testing/slow", paramXml("delay-ms", "20")) +
                 recorder("rec", "out.csv"),
             filterXml("l", "latest"),
             connectXml("src.out", "l.in") + connectXml("l.out", "reader.in") +
                 connectXml("reader.endIt", "l.sync") + connectXml("reader.out", "rec.in")));
  const auto counters = recordedCounters(dir.file("out.csv"));
  ASSERT_FALSE(counters.empty());
  expectIncreasing(counters);
  EXPECT_EQ(counters.back(), 1999) << "the newest message is delivered in the end";
  // At 20 ms a sample, delivering half of them would take 20 s: older ones were dropped.
  EXPECT_LT(counters.size(), 1000u);
}

TEST_F(SamplingFilters, MaxFrequencyPacesEveryMessageToTheGivenRate) {
  const double seconds = run(appXml(source("src", 11) + recorder("rec", "out.csv"),
                                    filterXml("m", "maxfrequency", paramXml("frequency", "20")),
                                    connectXml("src.out", "m.in") + connectXml("m.out", "rec.in")));
  std::vector<long> all;
  for (long i = 0; i < 11; ++i) all.push_back(i);
  EXPECT_EQ(recordedCounters(dir.file("out.csv")), all) << "mode wait: nothing is lost";
  EXPECT_GE(seconds, 0.5) << "11 messages at most 20 per second take 10 periods of 50 ms";
}

TEST_F(SamplingFilters, MaxFrequencyLatestModeDropsAllButTheNewest) {
  const double seconds = run(appXml(
      source("src", 5000) + recorder("rec", "out.csv"),
      filterXml("m", "maxfrequency", paramXml("frequency", "20") + paramXml("mode", "latest")),
      connectXml("src.out", "m.in") + connectXml("m.out", "rec.in")));
  const auto counters = recordedCounters(dir.file("out.csv"));
  ASSERT_FALSE(counters.empty());
  expectIncreasing(counters);
  EXPECT_EQ(counters.back(), 4999);
  EXPECT_LE(static_cast<double>(counters.size()), 20.0 * seconds + 1.0)
      << counters.size() << " messages in " << seconds << " s";
}

TEST_F(SamplingFilters, StampFilterForwardsTheOrderedIterationsAndSkipsMissingOnes) {
  // Orders 0, 3, ..., 30: iteration 30 never comes (the source stops at 29).
  run(appXml(
      source("src", 30) +
          moduleXml("ord", "testing/orders", paramXml("step", "3") + paramXml("count", "11")) +
          recorder("rec", "out.csv"),
      filterXml("sf", "stampfilter"),
      connectXml("src.out", "sf.in") + connectXml("ord.out", "sf.order") +
          connectXml("sf.out", "rec.in")));
  EXPECT_EQ(recordedCounters(dir.file("out.csv")),
            (std::vector<long>{0, 3, 6, 9, 12, 15, 18, 21, 24, 27}));
}

TEST_F(SamplingFilters, TypeFilterKeepsOnlyTheListedObjectTypes) {
  run(appXml(
      moduleXml("mix", "testing/mixed",
                paramXml("points", "2") + paramXml("rigids", "3") + paramXml("count", "5")) +
          recorder("points", "points.csv") + recorder("rigids", "rigids.csv"),
      filterXml("p", "typefilter", paramXml("types", "point")) +
          filterXml("r", "typefilter",
                    paramXml("types", "rigid, massspring") + paramXml("drop-others", "true")),
      connectXml("mix.out", "p.in") + connectXml("p.out", "points.in") +
          connectXml("mix.out", "r.in") + connectXml("r.out", "rigids.in")));
  std::map<std::string, int> points, rigids;
  for (const auto& row : readRecording(dir.file("points.csv"))) {
    ++points[row.kind == "object" ? (row.x.empty() ? "rigid" : "point") : row.kind];
  }
  for (const auto& row : readRecording(dir.file("rigids.csv"))) {
    ++rigids[row.kind == "object" ? (row.x.empty() ? "rigid" : "point") : row.kind];
  }
  EXPECT_EQ(points, (std::map<std::string, int>{{"point", 10}, {"resource", 5}, {"event", 5}}));
  EXPECT_EQ(rigids, (std::map<std::string, int>{{"rigid", 15}}));
}

TEST_F(SamplingFilters, ValidateAcceptsEveryStandardFilterAndChecksTheirParameters) {
  const std::string modules = source("src", 1) + recorder("rec", "x.csv");
  const auto chain = [](const std::string& id, const std::string& in, const std::string& out) {
    return connectXml("src.out", id + "." + in) + connectXml(id + "." + out, "rec.in");
  };
  const auto good = dir.write(
      "good.xml",
      appXml(modules,
             filterXml("mux", "multiplex") + filterXml("g", "gate") + filterXml("r", "rotate") +
                 filterXml("u", "unrotate") + filterXml("s", "scatter") + filterXml("j", "gather") +
                 filterXml("l", "latest") +
                 filterXml("m", "maxfrequency", paramXml("frequency", "0.5")) +
                 filterXml("sf", "stampfilter") +
                 filterXml("t", "typefilter", paramXml("types", "rigid")),
             chain("mux", "in0", "out") + connectXml("src.out", "mux.in1") +
                 chain("g", "in", "out") + connectXml("src.out", "g.open") +
                 chain("r", "in", "out0") + chain("u", "in0", "out") +
                 connectXml("r.out1", "u.in1") + chain("s", "in", "out0") +
                 chain("j", "in0", "out") + connectXml("s.out1", "j.in1") +
                 chain("l", "in", "out") + connectXml("rec.endIt", "l.sync") +
                 chain("m", "in", "out") + chain("sf", "in", "out") +
                 connectXml("src.endIt", "sf.order") + chain("t", "in", "out")));
  const auto ok = runVrflow({"validate", good});
  EXPECT_EQ(ok.exitCode, 0) << ok.err;

  const auto bad = dir.write(
      "bad.xml",
      appXml(modules,
             filterXml("m", "maxfrequency", paramXml("frequency", "0")) +
                 filterXml("g", "gate", paramXml("initially", "ajar")),
             chain("m", "in", "out") + chain("g", "in", "out") + connectXml("src.out", "g.open")));
  const auto refused = runVrflow({"validate", bad});
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_NE(refused.err.find("parameter 'frequency' of filter 'm' (maxfrequency) is 0, below its "
                             "minimum 0.001"),
            std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("parameter 'initially' of filter 'g' (gate) expects one of"),
            std::string::npos)
      << refused.err;
}

}  // namespace
}  // namespace vrflow::testing
