// `vrflow run --trace`: the message arrows (Chrome trace-event flows) of real runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

std::string application(const std::string& modules, const std::string& connections) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"trace\" version=\"1\">\n"
         "  <hosts>\n    <host id=\"h1\" address=\"127.0.0.1\"/>\n  </hosts>\n  <modules>\n" +
         modules + "  </modules>\n  <connections>\n" + connections +
         "  </connections>\n</application>\n";
}

std::string module(const std::string& id, const std::string& type, const std::string& params = "") {
  const auto slash = type.find('/');
  return "    <module id=\"" + id + "\" package=\"" + type.substr(0, slash) + "\" type=\"" +
         type.substr(slash + 1) + "\" host=\"h1\">\n" + params + "    </module>\n";
}

std::string connect(const std::string& from, const std::string& to) {
  return "    <connection from=\"" + from + "\" to=\"" + to + "\"/>\n";
}

// The arrows of a trace: per name ("sender -> receiver"), how many; and how many end before
// they start.
struct Arrows {
  std::map<std::string, int> byName;
  int backwards = 0;
  int total = 0;
};

Arrows arrowsOf(const std::string& path) {
  const auto trace = nlohmann::json::parse(readFile(path));
  std::map<uint64_t, double> starts;
  Arrows arrows;
  for (const auto& e : trace["traceEvents"]) {
    if (e["ph"] == "s") starts[e["id"].get<uint64_t>()] = e["ts"].get<double>();
  }
  for (const auto& e : trace["traceEvents"]) {
    if (e["ph"] != "f") continue;
    const auto start = starts.find(e["id"].get<uint64_t>());
    if (start == starts.end()) continue;
    ++arrows.total;
    ++arrows.byName[e["name"].get<std::string>()];
    if (e["ts"].get<double>() < start->second) ++arrows.backwards;
  }
  return arrows;
}

class TraceTest : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
    EXPECT_TRUE(vrflowShmEntries().empty()) << "shared-memory segments were left behind";
  }
  TempDir dir;
};

TEST_F(TraceTest, EveryArrowEndsAfterItStarts) {
  // Each relay wakes as soon as its sender rings the daemon: a send time taken after that
  // ring was later than the receipt now and then, more often on a busy machine (two threads
  // spin here meanwhile). r1 sleeps 1 ms per message so that the modules' trace rings (8192
  // events, drained every 50 ms) never overflow and every arrow is there; r2, r3 and rec still
  // wake on the doorbell at once.
  constexpr int kIterations = 3000;
  const auto file = dir.write(
      "app.xml",
      application(module("src", "core/source") +
                      module("r1", "core/relay", "      <param name=\"delay-ms\" value=\"1\"/>\n") +
                      module("r2", "core/relay") + module("r3", "core/relay") +
                      module("rec", "core/recorder",
                             "      <param name=\"file\" value=\"" + dir.file("x.csv") + "\"/>\n"),
                  connect("src.out", "r1.in") + connect("r1.out", "r2.in") +
                      connect("r2.out", "r3.in") + connect("r3.out", "rec.in")));
  std::atomic<bool> busy{true};
  std::vector<std::thread> spinners;
  for (int i = 0; i < 2; ++i) {
    spinners.emplace_back([&] {
      while (busy.load(std::memory_order_relaxed)) {
      }
    });
  }
  const auto result = runVrflow(
      {"run", file, "-n", std::to_string(kIterations), "--trace", dir.file("t.json")}, 120);
  busy = false;
  for (auto& t : spinners) t.join();
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto trace = nlohmann::json::parse(readFile(dir.file("t.json")));
  ASSERT_EQ(trace["otherData"]["dropped_events"], 0) << "the rings overflowed: arrows are missing";
  const auto arrows = arrowsOf(dir.file("t.json"));
  EXPECT_EQ(arrows.total, 4 * kIterations);
  EXPECT_EQ(arrows.backwards, 0) << "of " << arrows.total << " arrows";
}

TEST_F(TraceTest, AModuleThatForwardsAMessageUnchangedIsAHopOfItsOwn) {
  // testing/slow with copy=false puts the message it received: the stamps stay src's.
  const auto file = dir.write(
      "app.xml",
      application(module("src", "core/source") + module("fwd", "testing/slow") +
                      module("rec", "core/recorder",
                             "      <param name=\"file\" value=\"" + dir.file("x.csv") + "\"/>\n"),
                  connect("src.out", "fwd.in") + connect("fwd.out", "rec.in")));
  const auto result = runVrflow({"run", file, "-n", "30", "--trace", dir.file("t.json")}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  auto arrows = arrowsOf(dir.file("t.json"));
  EXPECT_EQ(arrows.byName["src -> fwd"], 30);
  EXPECT_EQ(arrows.byName["fwd -> rec"], 30);
  EXPECT_EQ(arrows.byName.count("src -> rec"), 0u) << "an arrow skips the forwarding module";
  EXPECT_EQ(arrows.backwards, 0);
}

TEST_F(TraceTest, EveryPartOfAMergedInputHasItsArrow) {
  // Two connections into one input, and a merge filter of three: one message each iteration
  // made of the parts of every sender.
  const auto file = dir.write(
      "app.xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"trace\" version=\"1\">\n"
      "  <hosts>\n    <host id=\"h1\" address=\"127.0.0.1\"/>\n  </hosts>\n  <modules>\n" +
          module("a", "core/source") + module("b", "core/source") + module("c", "core/source") +
          module("two", "core/recorder",
                 "      <param name=\"file\" value=\"" + dir.file("two.csv") + "\"/>\n") +
          module("three", "core/recorder",
                 "      <param name=\"file\" value=\"" + dir.file("three.csv") + "\"/>\n") +
          "  </modules>\n  <filters>\n    <filter id=\"m\" type=\"merge\">\n"
          "      <param name=\"inputs\" value=\"3\"/>\n    </filter>\n  </filters>\n"
          "  <connections>\n" +
          connect("a.out", "two.in") + connect("b.out", "two.in") + connect("a.out", "m.in0") +
          connect("b.out", "m.in1") + connect("c.out", "m.in2") + connect("m.out", "three.in") +
          "  </connections>\n</application>\n");
  const auto result = runVrflow({"run", file, "-n", "25", "--trace", dir.file("t.json")}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  auto arrows = arrowsOf(dir.file("t.json"));
  EXPECT_EQ(arrows.byName["a -> two"], 25);
  EXPECT_EQ(arrows.byName["b -> two"], 25);
  EXPECT_EQ(arrows.byName["a -> three"], 25);
  EXPECT_EQ(arrows.byName["b -> three"], 25);
  EXPECT_EQ(arrows.byName["c -> three"], 25);
  EXPECT_EQ(arrows.backwards, 0);
}

// The start times of the arrows named `name`, in order.
std::vector<double> arrowStarts(const std::string& path, const std::string& name) {
  const auto trace = nlohmann::json::parse(readFile(path));
  std::vector<double> starts;
  for (const auto& e : trace["traceEvents"]) {
    if (e["ph"] == "s" && e["name"] == name) starts.push_back(e["ts"].get<double>());
  }
  std::sort(starts.begin(), starts.end());
  return starts;
}

TEST_F(TraceTest, AMessageRenumberedByRepeatOrDecimateStartsAtItsOriginalsPut) {
  // repeat (count 4) sends src's message i as iterations 4i..4i+3, decimate (count 4) sends
  // src's message 4g+3 as iteration g: each arrow starts at the put of the message it carries,
  // never at the put of src's message of the renumbered iteration (a later one for repeat: the
  // arrow ran backwards).
  const auto recorder = [&](const std::string& id) {
    return module(id, "core/recorder",
                  "      <param name=\"file\" value=\"" + dir.file(id + ".csv") + "\"/>\n");
  };
  const auto file = dir.write(
      "app.xml",
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"trace\" version=\"1\">\n"
      "  <hosts>\n    <host id=\"h1\" address=\"127.0.0.1\"/>\n  </hosts>\n  <modules>\n" +
          module("src", "core/source") + recorder("direct") + recorder("fast") + recorder("slow") +
          "  </modules>\n  <filters>\n"
          "    <filter id=\"up\" type=\"repeat\"><param name=\"count\" value=\"4\"/></filter>\n"
          "    <filter id=\"down\" type=\"decimate\"><param name=\"count\" value=\"4\"/></filter>\n"
          "  </filters>\n  <connections>\n" +
          connect("src.out", "direct.in") + connect("src.out", "up.in") +
          connect("up.out", "fast.in") + connect("src.out", "down.in") +
          connect("down.out", "slow.in") + "  </connections>\n</application>\n");
  const auto result = runVrflow({"run", file, "-n", "40", "--trace", dir.file("t.json")}, 60);
  ASSERT_EQ(result.exitCode, 0) << result.err;
  auto arrows = arrowsOf(dir.file("t.json"));
  EXPECT_EQ(arrows.byName["src -> direct"], 40);
  EXPECT_EQ(arrows.byName["src -> fast"], 160);
  EXPECT_EQ(arrows.byName["src -> slow"], 10);
  EXPECT_EQ(arrows.backwards, 0);
  // src's puts, in order, as the direct receiver's arrows start at them.
  const auto puts = arrowStarts(dir.file("t.json"), "src -> direct");
  ASSERT_EQ(puts.size(), 40u);
  const auto fast = arrowStarts(dir.file("t.json"), "src -> fast");
  ASSERT_EQ(fast.size(), 160u);
  for (std::size_t r = 0; r < fast.size(); ++r) EXPECT_EQ(fast[r], puts[r / 4]) << r;
  const auto slow = arrowStarts(dir.file("t.json"), "src -> slow");
  ASSERT_EQ(slow.size(), 10u);
  for (std::size_t g = 0; g < slow.size(); ++g) EXPECT_EQ(slow[g], puts[4 * g + 3]) << g;
}

}  // namespace
}  // namespace vrflow::testing
