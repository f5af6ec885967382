// End-to-end tests of the routing filters (docs/filters.md): multiplex, gate, rotate/unrotate,
// scatter/gather. Each runs the real `vrflow` and checks what core/recorder received.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

class RoutingFilters : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  void run(const std::string& xml) {
    const auto result = runVrflow({"run", dir.write("app.xml", xml), "--timeout", "60"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
  }
  std::string recorder(const std::string& id, const std::string& csv) {
    return moduleXml(id, "core/recorder", paramXml("file", dir.file(csv)));
  }
  TempDir dir;
};

std::string source(const std::string& id, int count, int size = 64) {
  return moduleXml(
      id, "core/source",
      paramXml("count", std::to_string(count)) + paramXml("size", std::to_string(size)));
}

uint64_t splitmix64(uint64_t id) {
  id += 0x9e3779b97f4a7c15ULL;
  id = (id ^ (id >> 30)) * 0xbf58476d1ce4e5b9ULL;
  id = (id ^ (id >> 27)) * 0x94d049bb133111ebULL;
  return id ^ (id >> 31);
}

TEST_F(RoutingFilters, MultiplexForwardsEveryMessageRenumberedByArrival) {
  run(appXml(source("a", 15, 16) + source("b", 15, 32) + recorder("rec", "out.csv"),
             filterXml("mux", "multiplex"),
             connectXml("a.out", "mux.in0") + connectXml("b.out", "mux.in1") +
                 connectXml("mux.out", "rec.in")));
  const auto rows = readRecording(dir.file("out.csv"));
  ASSERT_EQ(rows.size(), 30u);
  std::map<std::string, long> next{{"a", 0}, {"b", 0}};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].sourceIteration, static_cast<long>(i)) << "renumbered by the running count";
    ASSERT_TRUE(next.count(rows[i].source)) << rows[i].source;
    EXPECT_EQ(rows[i].y, rows[i].source == "a" ? "16" : "32");
    EXPECT_EQ(std::stol(rows[i].x), next[rows[i].source]++) << "each input keeps its order";
  }
  EXPECT_EQ(next["a"], 15);
  EXPECT_EQ(next["b"], 15);
}

// The control source and the data source run in lockstep (endIt -> beginIt both ways), so
// control message i always reaches the gate before data message i and after data i-1.
std::string gatedApp(const std::string& pattern, const std::string& csv) {
  return appXml(moduleXml("ctl", "testing/toggle",
                          paramXml("pattern", pattern) +
                              "      <input port=\"beginIt\" initial-messages=\"1\"/>\n") +
                    source("src", 20) + moduleXml("rec", "core/recorder", paramXml("file", csv)),
                filterXml("g", "gate"),
                connectXml("ctl.out", "g.open") + connectXml("src.out", "g.in") +
                    connectXml("g.out", "rec.in") + connectXml("ctl.endIt", "src.beginIt") +
                    connectXml("src.endIt", "ctl.beginIt"));
}

TEST_F(RoutingFilters, GateForwardsWhileOpenAndDropsWhileClosed) {
  run(gatedApp("1100", dir.file("out.csv")));
  EXPECT_EQ(recordedCounters(dir.file("out.csv")),
            (std::vector<long>{0, 1, 4, 5, 8, 9, 12, 13, 16, 17}));
}

TEST_F(RoutingFilters, GateOpenStampDecidesOverTheChunkRule) {
  // 1: chunk (open), c: chunk with open=0 (closed), 0: empty (closed), o: empty with open=1.
  run(gatedApp("1c0o", dir.file("out.csv")));
  EXPECT_EQ(recordedCounters(dir.file("out.csv")),
            (std::vector<long>{0, 3, 4, 7, 8, 11, 12, 15, 16, 19}));
}

std::string workersApp(const std::string& order, bool copy, const std::string& csv) {
  std::string workers, connections;
  const char* delays[] = {"0", "4", "1"};
  for (int w = 0; w < 3; ++w) {
    const std::string id = "w" + std::to_string(w);
    workers +=
        moduleXml(id, "testing/slow",
                  paramXml("delay-ms", delays[w]) + paramXml("copy", copy ? "true" : "false"));
    connections += connectXml("r.out" + std::to_string(w), id + ".in") +
                   connectXml(id + ".out", "u.in" + std::to_string(w));
  }
  return appXml(
      source("src", 30) + workers + moduleXml("rec", "core/recorder", paramXml("file", csv)),
      filterXml("r", "rotate", paramXml("outputs", "3")) +
          filterXml("u", "unrotate", paramXml("inputs", "3") + paramXml("order", order)),
      connectXml("src.out", "r.in") + connections + connectXml("u.out", "rec.in"));
}

std::vector<long> zeroTo(long n) {
  std::vector<long> values;
  for (long i = 0; i < n; ++i) values.push_back(i);
  return values;
}

TEST_F(RoutingFilters, UnrotatePutsResultsOfSlowWorkersBackInOrderByIteration) {
  run(workersApp("iteration", false, dir.file("out.csv")));
  const auto rows = readRecording(dir.file("out.csv"));
  EXPECT_EQ(recordedCounters(dir.file("out.csv")), zeroTo(30));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].source, "src");  // forwarded by reference: the source's stamps
    EXPECT_EQ(rows[i].sourceIteration, static_cast<long>(i));
  }
}

TEST_F(RoutingFilters, UnrotateOrdersWorkersThatNumberTheirOwnResults) {
  for (const std::string order : {"iteration", "round-robin"}) {
    SCOPED_TRACE(order);
    const auto csv = dir.file(order + ".csv");
    run(workersApp(order, true, csv));
    EXPECT_EQ(recordedCounters(csv), zeroTo(30));
    const auto rows = readRecording(csv);
    ASSERT_EQ(rows.size(), 30u);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      EXPECT_EQ(rows[i].source, "w" + std::to_string(i % 3));  // worker k had messages k, k+3...
      EXPECT_EQ(rows[i].sourceIteration, static_cast<long>(i / 3));
    }
  }
}

std::string mixed(const std::string& id, int points, int rigids, int count) {
  return moduleXml(id, "testing/mixed",
                   paramXml("points", std::to_string(points)) +
                       paramXml("rigids", std::to_string(rigids)) +
                       paramXml("count", std::to_string(count)));
}

TEST_F(RoutingFilters, ScatterByChunkThenGatherGivesBackEveryMessage) {
  run(appXml(mixed("mix", 3, 2, 10) + recorder("whole", "whole.csv") +
                 recorder("joined", "joined.csv") + recorder("first", "first.csv") +
                 recorder("last", "last.csv"),
             filterXml("s", "scatter", paramXml("outputs", "3")) +
                 filterXml("g", "gather", paramXml("inputs", "3")),
             connectXml("mix.out", "whole.in") + connectXml("mix.out", "s.in") +
                 connectXml("s.out0", "g.in0") + connectXml("s.out1", "g.in1") +
                 connectXml("s.out2", "g.in2") + connectXml("g.out", "joined.in") +
                 connectXml("s.out0", "first.in") + connectXml("s.out2", "last.in")));
  const auto whole = readLines(dir.file("whole.csv"));
  ASSERT_EQ(whole.size(), 1u + 10u * 7u);  // 3 points, 2 rigids, a resource, a force
  EXPECT_EQ(readLines(dir.file("joined.csv")), whole);
  // 7 chunks in 3 contiguous runs: 3, 2, 2.
  const auto first = readRecording(dir.file("first.csv"));
  const auto last = readRecording(dir.file("last.csv"));
  ASSERT_EQ(first.size(), 30u);
  ASSERT_EQ(last.size(), 20u);
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].kind, "object");
    EXPECT_EQ(first[i].x, std::to_string(i % 3));                   // points k = 0, 1, 2
    EXPECT_EQ(first[i].sourceIteration, static_cast<long>(i / 3));  // the message's stamps
  }
  for (std::size_t i = 0; i < last.size(); ++i) {
    EXPECT_EQ(last[i].kind, i % 2 == 0 ? "resource" : "event");
  }
}

TEST_F(RoutingFilters, ScatterByIdSendsEachChunkToTheOutputOfItsIdsHash) {
  run(appXml(mixed("mix", 4, 4, 5) + recorder("r0", "r0.csv") + recorder("r1", "r1.csv"),
             filterXml("s", "scatter", paramXml("outputs", "2") + paramXml("by", "id")),
             connectXml("mix.out", "s.in") + connectXml("s.out0", "r0.in") +
                 connectXml("s.out1", "r1.in")));
  std::set<std::string> objects;
  std::size_t chunks = 0;
  for (int output = 0; output < 2; ++output) {
    std::set<long> iterations;
    for (const auto& row : readRecording(dir.file("r" + std::to_string(output) + ".csv"))) {
      iterations.insert(row.iteration);
      if (row.kind == "empty") continue;
      ++chunks;
      EXPECT_EQ(splitmix64(std::stoull(row.id)) % 2, static_cast<uint64_t>(output)) << row.id;
      if (row.kind == "object") objects.insert(row.id);
    }
    EXPECT_EQ(iterations.size(), 5u) << "one part per message, even an empty one";
  }
  EXPECT_EQ(objects.size(), 8u);
  EXPECT_EQ(chunks, 5u * 10u);  // every chunk went to exactly one output
}

TEST_F(RoutingFilters, ScatterByTypeSendsEachListedTypeToItsOutput) {
  run(appXml(mixed("mix", 2, 3, 5) + recorder("points", "points.csv") +
                 recorder("rigids", "rigids.csv") + recorder("only", "only.csv"),
             filterXml("s", "scatter", paramXml("by", "type") + paramXml("types", "point, rigid")) +
                 filterXml("d", "scatter",
                           paramXml("by", "type") + paramXml("types", "point,rigid") +
                               paramXml("others", "drop")),
             connectXml("mix.out", "s.in") + connectXml("s.out0", "points.in") +
                 connectXml("s.out1", "rigids.in") + connectXml("mix.out", "d.in") +
                 connectXml("d.out0", "only.in")));
  const auto count = [](const std::vector<RecordedChunk>& rows, const std::string& kind,
                        bool point) {
    std::size_t n = 0;
    for (const auto& row : rows)
      n += row.kind == kind && (kind != "object" || !row.x.empty() == point);
    return n;
  };
  const auto points = readRecording(dir.file("points.csv"));
  const auto rigids = readRecording(dir.file("rigids.csv"));
  const auto only = readRecording(dir.file("only.csv"));
  EXPECT_EQ(count(points, "object", true), 10u);
  EXPECT_EQ(count(points, "object", false), 0u);
  EXPECT_EQ(count(rigids, "object", false), 15u);
  EXPECT_EQ(count(rigids, "object", true), 0u);
  for (const auto* rows : {&points, &rigids}) {  // others=all: to every output
    EXPECT_EQ(count(*rows, "resource", false), 5u);
    EXPECT_EQ(count(*rows, "event", false), 5u);
  }
  EXPECT_EQ(only.size(), 10u);  // others=drop: the points only
  EXPECT_EQ(count(only, "object", true), 10u);
}

// Points at x = 0, 1, 2; rigid k at x = k with bounds x +- 0.75 in the first message only, so
// rigid 0 meets the slabs below 0.5 and [0.5, 1.5), rigid 1 all three; later updates carry no
// bounds and follow the latest known ones, and so do the deletes of the rigids in the last one.
TEST_F(RoutingFilters, ScatterByBoundsSendsObjectsToEverySlabTheirBoundsMeet) {
  run(appXml(
      moduleXml("mix", "testing/mixed",
                paramXml("points", "3") + paramXml("rigids", "2") + paramXml("count", "5") +
                    paramXml("extent", "0.75")) +
          recorder("a", "a.csv") + recorder("b", "b.csv") + recorder("c", "c.csv") +
          recorder("low", "low.csv") + recorder("high", "high.csv"),
      filterXml("s", "scatter",
                paramXml("outputs", "3") + paramXml("by", "bounds") + paramXml("axis", "x") +
                    paramXml("cuts", "0.5, 1.5")) +
          filterXml(
              "d", "scatter",
              paramXml("by", "bounds") + paramXml("cuts", "1.5") + paramXml("others", "drop")),
      connectXml("mix.out", "s.in") + connectXml("s.out0", "a.in") + connectXml("s.out1", "b.in") +
          connectXml("s.out2", "c.in") + connectXml("mix.out", "d.in") +
          connectXml("d.out0", "low.in") + connectXml("d.out1", "high.in")));
  struct Seen {
    std::multiset<double> pointXs;
    std::map<std::string, std::size_t> rigids;  // id -> chunks
    std::size_t resources = 0, events = 0;
    std::set<long> iterations;
  };
  const auto seen = [&](const std::string& csv) {
    Seen result;
    for (const auto& row : readRecording(dir.file(csv))) {
      result.iterations.insert(row.sourceIteration);
      if (row.kind == "object" && !row.x.empty()) result.pointXs.insert(std::stod(row.x));
      if (row.kind == "object" && row.x.empty()) ++result.rigids[row.id];
      result.resources += row.kind == "resource";
      result.events += row.kind == "event";
    }
    return result;
  };
  const Seen a = seen("a.csv"), b = seen("b.csv"), c = seen("c.csv");
  const Seen low = seen("low.csv"), high = seen("high.csv");
  EXPECT_EQ(a.pointXs, (std::multiset<double>{0, 0, 0, 0, 0}));
  EXPECT_EQ(b.pointXs, (std::multiset<double>{1, 1, 1, 1, 1}));
  EXPECT_EQ(c.pointXs, (std::multiset<double>{2, 2, 2, 2, 2}));
  // Both rigids meet out0 and out1 in every message (latest bounds); only rigid 1 meets out2.
  ASSERT_EQ(a.rigids.size(), 2u);
  EXPECT_EQ(b.rigids, a.rigids);
  ASSERT_EQ(c.rigids.size(), 1u);
  for (const auto& [id, chunks] : a.rigids) EXPECT_EQ(chunks, 5u) << id;
  EXPECT_EQ(c.rigids.begin()->second, 5u);
  EXPECT_TRUE(a.rigids.count(c.rigids.begin()->first));
  for (const Seen* out : {&a, &b, &c}) {  // others=all: resources and events to every output
    EXPECT_EQ(out->resources, 5u);
    EXPECT_EQ(out->events, 5u);
    EXPECT_EQ(out->iterations.size(), 5u);
  }
  // others=drop, one cut at 1.5: points 0 and 1 and both rigids low; point 2 and rigid 1 high.
  EXPECT_EQ(low.pointXs, (std::multiset<double>{0, 0, 0, 0, 0, 1, 1, 1, 1, 1}));
  EXPECT_EQ(high.pointXs, (std::multiset<double>{2, 2, 2, 2, 2}));
  EXPECT_EQ(low.rigids, a.rigids);
  EXPECT_EQ(high.rigids, c.rigids);
  for (const Seen* out : {&low, &high}) {
    EXPECT_EQ(out->resources, 0u);
    EXPECT_EQ(out->events, 0u);
  }
}

// 100 bytes of 8-byte elements in 3 parts: 12 elements as 4 + 4 + 4, the 4 bytes left over in
// the last part; each part prefixed by its offset and the total size.
TEST_F(RoutingFilters, ScatterBySizeThenGatherRebuildsTheOriginalBytes) {
  run(appXml(moduleXml("mix", "testing/mixed",
                       paramXml("points", "2") + paramXml("rigids", "1") + paramXml("count", "6") +
                           paramXml("payload", "100")) +
                 recorder("joined", "joined.csv") + recorder("first", "first.csv") +
                 moduleXml("check", "testing/rebuild", paramXml("file", dir.file("rebuild.csv"))),
             filterXml("s", "scatter",
                       paramXml("outputs", "3") + paramXml("by", "size") +
                           paramXml("element-size", "8") + paramXml("others", "drop")) +
                 filterXml("g", "gather", paramXml("inputs", "3")) +
                 filterXml("a", "scatter",
                           paramXml("outputs", "2") + paramXml("by", "size") +
                               paramXml("element-size", "8")),
             connectXml("mix.out", "s.in") + connectXml("s.out0", "g.in0") +
                 connectXml("s.out1", "g.in1") + connectXml("s.out2", "g.in2") +
                 connectXml("g.out", "joined.in") + connectXml("g.out", "check.in") +
                 connectXml("mix.out", "a.in") + connectXml("a.out0", "first.in")));
  const auto joined = readRecording(dir.file("joined.csv"));
  ASSERT_EQ(joined.size(), 6u * 3u) << "three resource parts per message, nothing else";
  for (std::size_t i = 0; i < joined.size(); ++i) {
    EXPECT_EQ(joined[i].kind, "resource");
    EXPECT_EQ(joined[i].sourceIteration, static_cast<long>(i / 3));
    EXPECT_EQ(joined[i].x, std::to_string(std::vector<int>{0, 32, 64}[i % 3])) << "offset";
    EXPECT_EQ(joined[i].y, std::to_string(std::vector<int>{48, 48, 52}[i % 3])) << "size";
  }
  const std::string rebuilt = readFile(dir.file("rebuild.csv"));
  std::string expected = "iteration,parts,total,ok\n";
  for (int it = 0; it < 6; ++it) expected += std::to_string(it) + ",3,100,ok\n";
  EXPECT_EQ(rebuilt, expected);
  // others=all: objects and events go with every part; 100 bytes = 12 elements, 6 + 6 + 4.
  std::size_t objects = 0, events = 0, resources = 0;
  for (const auto& row : readRecording(dir.file("first.csv"))) {
    objects += row.kind == "object";
    events += row.kind == "event";
    if (row.kind == "resource") {
      ++resources;
      EXPECT_EQ(row.x, "0");
      EXPECT_EQ(row.y, "64");
    }
  }
  EXPECT_EQ(objects, 6u * 3u);
  EXPECT_EQ(events, 6u);
  EXPECT_EQ(resources, 6u);
}

}  // namespace
}  // namespace vrflow::testing
