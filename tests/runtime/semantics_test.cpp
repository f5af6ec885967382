// End-to-end tests of run semantics that FlowVR's example networks exposed: how iterations are
// counted and when a run ends (`--iterations`, greedy inputs, producers nobody listens to),
// user stamps through merging filters, endIt timing, and the filters' per-port counters.
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

class Semantics : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  // `vrflow run` of `xml` with a report; `extra` are more options.
  CommandResult run(const std::string& xml, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"run", dir.write("app.xml", xml), "--report",
                                  dir.file("report.json"), "--no-progress"};
    args.insert(args.end(), extra.begin(), extra.end());
    if (std::find(extra.begin(), extra.end(), "--timeout") == extra.end()) {
      args.insert(args.end(), {"--timeout", "60"});
    }
    return runVrflow(args, 90);
  }
  nlohmann::json report() { return nlohmann::json::parse(readFile(dir.file("report.json"))); }
  nlohmann::json moduleOf(const nlohmann::json& json, const std::string& id) {
    for (const auto& m : json["modules"]) {
      if (m["id"] == id) return m;
    }
    ADD_FAILURE() << "no module " << id << " in the report";
    return {};
  }
  nlohmann::json filterOf(const nlohmann::json& json, const std::string& id) {
    for (const auto& f : json["filters"]) {
      if (f["id"] == id) return f;
    }
    ADD_FAILURE() << "no filter " << id << " in the report";
    return nlohmann::json::object();
  }
  std::string phases(const std::string& id, const std::string& params,
                     const std::string& attributes = "") {
    std::string xml =
        moduleXml(id, "testing/phases", paramXml("log", dir.file("phases.log")) + params);
    if (!attributes.empty()) xml.replace(xml.find("<module ") + 8, 0, attributes + " ");
    return xml;
  }
  TempDir dir;
};

std::string source(const std::string& id, int count) {
  return moduleXml(id, "core/source", paramXml("count", std::to_string(count)));
}

// ---- item 18: a module that leaves its loop after N iterations did N ------------------------

TEST_F(Semantics, AModuleThatLeavesItsLoopAfterSevenIterationsIsReportedWithSeven) {
  const auto result = run(appXml(phases("p", paramXml("count", "7")), "", ""));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto p = moduleOf(report(), "p");
  EXPECT_EQ(p["iterations"], 7) << "the iteration in progress when it left counts";
  EXPECT_EQ(p["end"], "left its loop");
}

TEST_F(Semantics, ASourceOfCountFiveStillReportsFiveAndItsConsumerToo) {
  const auto result =
      run(appXml(source("src", 5) + phases("c", ""), "", connectXml("src.out", "c.in")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report();
  EXPECT_EQ(moduleOf(json, "src")["iterations"], 5);
  EXPECT_EQ(moduleOf(json, "c")["iterations"], 5);
  EXPECT_EQ(moduleOf(json, "c")["end"], "end of input");
}

// ---- item 13: --iterations N and greedy consumers ------------------------------------------

// A fast producer, a `latest` filter synced by a slow consumer: the producer does its N first,
// and the consumer still gets the newest message until it has done N too.
TEST_F(Semantics, IterationsLetAGreedyConsumerBehindLatestReachItsCount) {
  const auto result =
      run(appXml(source("fast", 0) + moduleXml("slow", "testing/slow", paramXml("delay-ms", "5")),
                 filterXml("l", "latest"),
                 connectXml("fast.out", "l.in") + connectXml("l.out", "slow.in") +
                     connectXml("slow.endIt", "l.sync")),
          {"--iterations", "100"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report();
  EXPECT_EQ(moduleOf(json, "fast")["iterations"], 100);
  EXPECT_EQ(moduleOf(json, "slow")["iterations"], 100);
  EXPECT_EQ(moduleOf(json, "slow")["end"], "iteration count");
}

TEST_F(Semantics, IterationsLetAGreedyInputPortReachItsCount) {
  const auto result =
      run(appXml(source("fast", 0) + moduleXml("slow", "testing/slow",
                                               paramXml("delay-ms", "5") +
                                                   "      <input port=\"in\" mode=\"latest\"/>\n"),
                 "", connectXml("fast.out", "slow.in")),
          {"--iterations", "60"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(moduleOf(report(), "slow")["iterations"], 60);
}

// A producer that stops at 5 by itself cannot feed a consumer 10 times: the run says so.
TEST_F(Semantics, AModuleShortOfItsIterationsFailsTheRunNamingItAndWhy) {
  const auto result =
      run(appXml(source("src", 5) + phases("c", ""), "", connectXml("src.out", "c.in")),
          {"--iterations", "10"});
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE(result.err.find("module 'c' did 5 of 10 iterations (end of input)"), std::string::npos)
      << result.err;
  const auto json = report();
  EXPECT_EQ(json["status"], "short");
  EXPECT_EQ(moduleOf(json, "c")["end"], "end of input");
}

// ---- item 14: a producer whose consumers have all ended is stopped ------------------------

TEST_F(Semantics, AProducerWhoseConsumersEndedIsStoppedAndTheRunEndsNormally) {
  const auto result = run(appXml(source("src", 0) + phases("c", paramXml("count", "5")), "",
                                 connectXml("src.out", "c.in")),
                          {"--timeout", "20"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report();
  EXPECT_EQ(json["status"], "ok");
  EXPECT_EQ(moduleOf(json, "c")["iterations"], 5);
  EXPECT_EQ(moduleOf(json, "src")["end"], "outputs unneeded");
}

// Along a chain, through a filter: the source is stopped once the last module ended, and the
// worker between them ends with its input.
TEST_F(Semantics, AChainBehindAFilterEndsWhenItsLastModuleEnds) {
  const auto result =
      run(appXml(source("src", 0) + moduleXml("mid", "testing/slow", paramXml("delay-ms", "0")) +
                     phases("c", paramXml("count", "5")),
                 filterXml("m", "maxfrequency", paramXml("frequency", "1000")),
                 connectXml("src.out", "mid.in") + connectXml("mid.out", "m.in") +
                     connectXml("m.out", "c.in")),
          {"--timeout", "20"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report();
  EXPECT_EQ(moduleOf(json, "src")["end"], "outputs unneeded");
  EXPECT_EQ(moduleOf(json, "mid")["end"], "end of input") << "it ends with what was buffered";
}

// ---- item 15: user stamps through merge, gather and the default input filter --------------

std::string stamper(const std::string& id, const std::string& value, const std::string& weight,
                    const std::string& log = "") {
  return moduleXml(id, "testing/stamps",
                   paramXml("value", value) + paramXml("weight", weight) + paramXml("count", "3") +
                       (log.empty() ? "" : paramXml("log", log)));
}

TEST_F(Semantics, MergeKeepsTheUserStampsOfTheFirstMessage) {
  const auto result = run(appXml(stamper("a", "3", "1.5") + stamper("b", "4", "2.5") +
                                     stamper("sink", "0", "0", dir.file("stamps.log")),
                                 filterXml("m", "merge"),
                                 connectXml("a.out", "m.in0") + connectXml("b.out", "m.in1") +
                                     connectXml("m.out", "sink.in")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readLines(dir.file("stamps.log")),
            std::vector<std::string>(3, "value=3 weight=1.5 name=a"));
}

TEST_F(Semantics, MergeAndGatherCombineTheListedStampsBySumMinOrMax) {
  const auto result =
      run(appXml(stamper("a", "3", "1.5") + stamper("b", "4", "2.5") + stamper("c", "-2", "0.5") +
                     stamper("sum", "0", "0", dir.file("sum.log")) +
                     stamper("min", "0", "0", dir.file("min.log")),
                 filterXml("m", "merge",
                           paramXml("inputs", "3") + paramXml("stamps", "value:sum, weight:max")) +
                     filterXml("g", "gather",
                               paramXml("inputs", "3") +
                                   paramXml("stamps", "value:min,weight:min,name:first")),
                 connectXml("a.out", "m.in0") + connectXml("b.out", "m.in1") +
                     connectXml("c.out", "m.in2") + connectXml("a.out", "g.in0") +
                     connectXml("b.out", "g.in1") + connectXml("c.out", "g.in2") +
                     connectXml("m.out", "sum.in") + connectXml("g.out", "min.in")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readLines(dir.file("sum.log")),
            std::vector<std::string>(3, "value=5 weight=2.5 name=a"));
  EXPECT_EQ(readLines(dir.file("min.log")),
            std::vector<std::string>(3, "value=-2 weight=0.5 name=a"));
}

TEST_F(Semantics, TheDefaultInputFilterKeepsTheUserStampsOfTheFirstConnection) {
  const auto result =
      run(appXml(stamper("a", "3", "1.5") + stamper("b", "4", "2.5") +
                     stamper("sink", "0", "0", dir.file("stamps.log")),
                 "", connectXml("a.out", "sink.in") + connectXml("b.out", "sink.in")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(readLines(dir.file("stamps.log")),
            std::vector<std::string>(3, "value=3 weight=1.5 name=a"));
}

TEST_F(Semantics, ValidateRefusesAMalformedStampRule) {
  const auto file = dir.write(
      "bad.xml", appXml(stamper("a", "1", "1") + stamper("b", "1", "1") + stamper("s", "0", "0"),
                        filterXml("m", "merge", paramXml("stamps", "value:average")),
                        connectXml("a.out", "m.in0") + connectXml("b.out", "m.in1") +
                            connectXml("m.out", "s.in")));
  const auto result = runVrflow({"validate", file});
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE(result.err.find("'value:average' is not name:first, name:sum, name:min or name:max"),
            std::string::npos)
      << result.err;
}

// ---- item 16: endIt timing ------------------------------------------------------------------

// How many of the producer's iterations began while the consumer was inside one of its own.
int overlappedIterations(const std::vector<std::string>& lines) {
  bool consumerBusy = false;
  int overlapped = 0;
  for (const auto& line : lines) {
    std::istringstream in(line);
    std::string id, what;
    in >> id >> what;
    if (id == "c") consumerBusy = what == "begin";
    if (id == "p" && what == "begin" && consumerBusy) ++overlapped;
  }
  return overlapped;
}

// p -> c, and c.endIt -> initial(1) -> p.beginIt: with the default timing p and c alternate;
// with endit="after-wait" (FlowVR's), p computes its next iteration while c computes. c
// computes 100 ms per iteration so that p is scheduled within it even on a loaded machine.
TEST_F(Semantics, EndItAfterWaitLetsAProducerComputeWhileItsConsumerComputes) {
  for (const std::string timing : {"", "after-iteration", "after-wait"}) {
    std::remove(dir.file("phases.log").c_str());
    const auto result =
        run(appXml(phases("p", "") + phases("c", paramXml("delay-ms", "100"),
                                            timing.empty() ? "" : "endit=\"" + timing + "\""),
                   filterXml("pace", "initial"),
                   connectXml("p.out", "c.in") + connectXml("c.endIt", "pace.in") +
                       connectXml("pace.out", "p.beginIt")),
            {"--iterations", "20"});
    ASSERT_EQ(result.exitCode, 0) << timing << ": " << result.err;
    const auto lines = readLines(dir.file("phases.log"));
    ASSERT_EQ(lines.size(), 80u) << timing;
    const int overlapped = overlappedIterations(lines);
    if (timing == "after-wait") {
      EXPECT_GE(overlapped, 10) << "of 20 iterations";
    } else {
      EXPECT_EQ(overlapped, 0) << timing << ": the default alternates strictly";
    }
  }
}

TEST_F(Semantics, ValidateRefusesAnUnknownEndItTiming) {
  const auto file = dir.write("bad.xml", appXml(phases("p", "", "endit=\"early\""), "", ""));
  const auto result = runVrflow({"validate", file});
  EXPECT_EQ(result.exitCode, 1);
  EXPECT_NE(result.err.find("after-iteration, after-wait"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("bad.xml:"), std::string::npos) << result.err;
}

// ---- item 17: what the filters drop is counted per port, with the reason --------------------

TEST_F(Semantics, AClosedGateCountsWhatItDrops) {
  const auto result = run(
      appXml(source("src", 0) + moduleXml("ctl", "testing/toggle", paramXml("pattern", "1000")) +
                 moduleXml("rec", "core/recorder", paramXml("file", dir.file("out.csv"))),
             filterXml("g", "gate"),
             connectXml("src.out", "g.in") + connectXml("ctl.out", "g.open") +
                 connectXml("g.out", "rec.in")),
      {"--iterations", "80"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto gate = filterOf(report(), "g");
  ASSERT_TRUE(gate.contains("inputs")) << gate;
  const auto in = gate["inputs"][0];
  const auto out = gate["outputs"][0];
  EXPECT_EQ(in["port"], "in");
  EXPECT_EQ(in["messages"], 80);
  EXPECT_GT(in["dropped_by_reason"]["gate closed"].get<int>(), 0) << gate;
  EXPECT_EQ(out["messages"].get<int>() + in["dropped"].get<int>(), 80) << gate;
  EXPECT_EQ(static_cast<int>(recordedCounters(dir.file("out.csv")).size()),
            out["messages"].get<int>());
}

TEST_F(Semantics, LatestCountsTheMessagesNewerOnesReplaced) {
  const auto result = run(
      appXml(source("fast", 2000) + moduleXml("slow", "testing/slow", paramXml("delay-ms", "10")),
             filterXml("l", "latest"),
             connectXml("fast.out", "l.in") + connectXml("l.out", "slow.in") +
                 connectXml("slow.endIt", "l.sync")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = report();
  const auto latest = filterOf(json, "l");
  const auto in = latest["inputs"][0];
  EXPECT_EQ(in["messages"], 2000);
  EXPECT_GT(in["dropped_by_reason"]["replaced by a newer message"].get<int>(), 0) << latest;
  // What reached the filter was sent, replaced, or still held when the run ended (at most 1).
  const int accounted = latest["outputs"][0]["messages"].get<int>() + in["dropped"].get<int>();
  EXPECT_GE(accounted, 1999) << latest;
  EXPECT_LE(accounted, 2000) << latest;
  EXPECT_EQ(latest["outputs"][0]["messages"], moduleOf(json, "slow")["iterations"]);
}

TEST_F(Semantics, AGreedyInputPortCountsWhatItReplaced) {
  const auto result = run(appXml(
      source("fast", 2000) +
          moduleXml("slow", "testing/slow",
                    paramXml("delay-ms", "10") + "      <input port=\"in\" mode=\"latest\"/>\n"),
      "", connectXml("fast.out", "slow.in")));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto input = filterOf(report(), "slow.in");
  EXPECT_EQ(input["type"], "port-input");
  EXPECT_EQ(input["inputs"][0]["port"], "fast.out");
  EXPECT_GT(input["inputs"][0]["dropped_by_reason"]["replaced by a newer message"].get<int>(), 0)
      << input;
}

}  // namespace
}  // namespace vrflow::testing
