// Bounded buffers and pacing through the implicit iteration ports.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <regex>

#include "app_text.hpp"
#include "process_helpers.hpp"

namespace vrflow::testing {
namespace {

class BuffersTest : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_TRUE(leftoverProcesses().empty()) << "processes were left behind";
  }
  TempDir dir;
};

// FlowVR's pacing: the consumer's endIt, through an initial-message filter, feeds the
// producer's beginIt, so the producer's iteration i waits for the consumer's iteration i - N.
TEST_F(BuffersTest, EndItThroughInitialMessagesKeepsTheProducerAtMostNAhead) {
  constexpr int kAhead = 2;
  const auto log = dir.file("order.log");
  const auto file = dir.write(
      "app.xml",
      appXml(moduleXml("producer", "core/points", paramXml("log", log) + paramXml("count", "1")) +
                 moduleXml("consumer", "core/spring", paramXml("log", log)),
             filterXml("pace", "initial", paramXml("count", std::to_string(kAhead))),
             connectXml("producer.objects", "consumer.objects") +
                 connectXml("consumer.endIt", "pace.in") +
                 connectXml("pace.out", "producer.beginIt")));
  const auto result = runVrflow({"run", file, "-n", "300"});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  int produced = 0, consumed = 0, worst = 0;
  for (const auto& line : readLines(log)) {
    if (line.rfind("producer ", 0) == 0) ++produced;
    if (line.rfind("consumer ", 0) == 0) ++consumed;
    worst = std::max(worst, produced - consumed);
  }
  EXPECT_EQ(produced, 300);
  EXPECT_EQ(consumed, 300);
  EXPECT_LE(worst, kAhead) << "the producer ran more than " << kAhead << " iterations ahead";
}

// A producer much faster than its consumer, for 100,000 messages: shared memory in use stays
// bounded by the buffers, under each drop policy; nothing accumulates.
class DropPolicy : public BuffersTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(DropPolicy, FastProducerRunsWithFlatMemory) {
  const auto report = dir.file("report.json");
  const auto file = dir.write(
      "app.xml", appXml(moduleXml("fast", "core/source",
                                  paramXml("size", "4096") + paramXml("count", "100000")) +
                            moduleXml("slow", "testing/slow", paramXml("delay-ms", "1")),
                        "",
                        connectXml("fast.out", "slow.in",
                                   std::string("capacity=\"8\" policy=\"") + GetParam() + "\"")));
  const auto result = runVrflow({"run", file, "--report", report});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = nlohmann::json::parse(readFile(report));
  EXPECT_EQ(json["modules"][0]["iterations"], 100000);
  const auto& connection = json["connections"][0];
  // drop-newest refuses the newcomer (not counted as queued); drop-oldest queues it and
  // evicts the oldest: either way every message is accounted for.
  const bool newest = std::string(GetParam()) == "drop-newest";
  EXPECT_EQ(
      connection["messages"].get<uint64_t>() + (newest ? connection["dropped"].get<uint64_t>() : 0),
      100000u);
  EXPECT_GT(connection["dropped"].get<uint64_t>(), 90000u) << "the consumer is ~1000x slower";
  // 8 queued + 36 in rings and the output filter, 8 KiB blocks each: well under 1 MiB.
  EXPECT_LT(json["timing"]["segment_peak_bytes"].get<uint64_t>(), 1u << 20);
}

INSTANTIATE_TEST_SUITE_P(Policies, DropPolicy, ::testing::Values("drop-oldest", "drop-newest"));

TEST_F(BuffersTest, BlockingPolicyHoldsTheProducerBackWithFlatMemory) {
  const auto report = dir.file("report.json");
  const auto file =
      dir.write("app.xml", appXml(moduleXml("fast", "core/source",
                                            paramXml("size", "4096") + paramXml("count", "3000")) +
                                      moduleXml("slow", "testing/slow", paramXml("delay-ms", "1")),
                                  "", connectXml("fast.out", "slow.in", "capacity=\"8\"")));
  const auto result = runVrflow({"run", file, "--report", report});
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto json = nlohmann::json::parse(readFile(report));
  EXPECT_EQ(json["modules"][1]["iterations"], 3000) << "nothing is lost";
  EXPECT_EQ(json["connections"][0]["dropped"], 0);
  EXPECT_LT(json["timing"]["segment_peak_bytes"].get<uint64_t>(), 1u << 20);
  // The queue is full for the whole run (over 3 s): reported once, naming it and its policy.
  EXPECT_EQ(json["connections"][0]["stayed_full"], true);
  ASSERT_EQ(json["warnings"].size(), 1u) << json["warnings"];
  EXPECT_EQ(json["warnings"][0],
            "connection fast.out -> slow.in stayed full (8 messages, policy block): 'slow' takes "
            "messages slower than 'fast' sends them, so 'slow' paces 'fast'");
  EXPECT_NE(result.err.find("warning: connection fast.out -> slow.in stayed full"),
            std::string::npos);
}

}  // namespace
}  // namespace vrflow::testing
