// The routing filters run in-process (FilterHarness): multiplex, gate, rotate, unrotate,
// scatter, route.
#include <gtest/gtest.h>

#include "harness_support.hpp"
#include "vrflow/message/builtin_types.hpp"

namespace vrflow::testing {
namespace {

using Iterations = std::vector<uint64_t>;

// A message with one point object per position of `at`, with iteration stamp `iteration`.
daemon::MessageRef pointsAt(FilterHarness& h, uint64_t iteration, std::vector<double> at) {
  return h.message([&](msg::MessageBuilder& builder) {
    builder.setIteration(iteration);
    for (std::size_t i = 0; i < at.size(); ++i) {
      builder.addObject(100 + i, msg::pointType(), msg::ObjectOp::Add)
          .set(msg::PointParam::kPosition, msg::Vec3{at[i], at[i], at[i]});
    }
  });
}

// The ids of the chunks of `message`.
std::vector<uint64_t> idsOf(const daemon::MessageRef& message) {
  std::vector<uint64_t> ids;
  const auto view = message.view();  // the range below must not outlive the Result
  for (const msg::ChunkView chunk : *view) ids.push_back(chunk.id());
  return ids;
}

TEST(MultiplexFilter, ForwardsEveryInputInTurnRenumbered) {
  auto h = harness("multiplex");
  ASSERT_TRUE(h);
  h->push("in0", h->stamped(10));
  h->push("in0", h->stamped(11));
  h->push("in1", h->stamped(20));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{0, 1, 2}));

  auto untouched = harness("multiplex", {{"renumber", "false"}});
  ASSERT_TRUE(untouched);
  untouched->push("in0", untouched->stamped(10));
  untouched->push("in0", untouched->stamped(11));
  untouched->push("in1", untouched->stamped(20));
  untouched->step();
  EXPECT_EQ(untouched->takeIterations("out"), (Iterations{10, 20, 11}));
}

TEST(MultiplexFilter, RefusesABadRenumberOrInputCount) {
  EXPECT_NE(refusal("multiplex", {{"renumber", "yes"}}), "");
  EXPECT_NE(refusal("multiplex", {{"inputs", "257"}}).find("above its maximum 256"),
            std::string::npos);
}

TEST(GateFilter, DropsWhileClosedAndForwardsOnceOpened) {
  auto h = harness("gate");
  ASSERT_TRUE(h);
  h->push("in", h->stamped(1));
  h->step();
  EXPECT_TRUE(h->take("out").empty());
  EXPECT_EQ(h->droppedOn("in"), 1u);
  h->push("open", h->message([](msg::MessageBuilder& b) { b.addInt64Stamp("open", 1); }));
  h->push("in", h->stamped(2));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{2}));
  h->push("open", h->message());  // no stamp, no chunk: closes
  h->push("in", h->stamped(3));
  h->step();
  EXPECT_TRUE(h->take("out").empty());
  EXPECT_EQ(h->droppedOn("in"), 2u);
}

TEST(GateFilter, StartsOpenWhenAskedAndRefusesAnUnknownState) {
  auto h = harness("gate", {{"initially", "open"}});
  ASSERT_TRUE(h);
  h->push("in", h->stamped(5));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{5}));
  EXPECT_NE(refusal("gate", {{"initially", "ajar"}}), "");
}

TEST(RotateFilter, DealsMessagesRoundRobinAndWaitsForAFullWorker) {
  auto h = harness("rotate", {{"outputs", "3"}});
  ASSERT_TRUE(h);
  for (uint64_t i = 0; i < 6; ++i) h->push("in", h->stamped(i));
  h->setRoom("out1", 1);
  h->step();
  // Strict turns: message 4 waits for out1, and message 5 behind it.
  EXPECT_EQ(h->takeIterations("out0"), (Iterations{0, 3}));
  EXPECT_EQ(h->takeIterations("out1"), (Iterations{1}));
  EXPECT_EQ(h->takeIterations("out2"), (Iterations{2}));
  h->setRoom("out1", 10);
  h->step();
  EXPECT_EQ(h->takeIterations("out1"), (Iterations{4}));
  EXPECT_EQ(h->takeIterations("out2"), (Iterations{5}));
  EXPECT_NE(refusal("rotate", {{"outputs", "0"}}).find("below its minimum 1"), std::string::npos);
}

TEST(UnrotateFilter, PutsResultsBackInIterationOrderOrInTurn) {
  auto h = harness("unrotate");
  ASSERT_TRUE(h);
  h->push("in1", h->stamped(1));
  h->step();
  EXPECT_TRUE(h->take("out").empty());  // in0 may still bring an older result
  h->push("in0", h->stamped(0));
  h->push("in0", h->stamped(2));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{0, 1}));  // 2 waits for in1's next

  auto turns = harness("unrotate", {{"order", "round-robin"}});
  ASSERT_TRUE(turns);
  turns->push("in0", turns->stamped(9));
  turns->push("in1", turns->stamped(3));
  turns->push("in0", turns->stamped(1));
  turns->step();
  EXPECT_EQ(turns->takeIterations("out"), (Iterations{9, 3, 1}));
  EXPECT_NE(refusal("unrotate", {{"order", "random"}}), "");
}

TEST(ScatterFilter, SplitsTheChunksIntoContiguousRunsWithTheStamps) {
  auto h = harness("scatter", {{"outputs", "2"}});
  ASSERT_TRUE(h);
  h->push("in", pointsAt(*h, 7, {0, 1, 2, 3}));
  h->step();
  const auto first = h->take("out0");
  const auto second = h->take("out1");
  ASSERT_EQ(first.size(), 1u);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(idsOf(first[0]), (std::vector<uint64_t>{100, 101}));
  EXPECT_EQ(idsOf(second[0]), (std::vector<uint64_t>{102, 103}));
  EXPECT_EQ(second[0].view()->stamps().iteration, 7u);
}

TEST(ScatterFilter, SplitsByBoundsAlongTheCuts) {
  auto h = harness("scatter", {{"outputs", "2"}, {"by", "bounds"}, {"cuts", "1.5"}});
  ASSERT_TRUE(h);
  h->push("in", pointsAt(*h, 0, {0, 5, 1}));
  h->step();
  EXPECT_EQ(idsOf(h->take("out0").at(0)), (std::vector<uint64_t>{100, 102}));
  EXPECT_EQ(idsOf(h->take("out1").at(0)), (std::vector<uint64_t>{101}));
}

TEST(ScatterFilter, RefusesParametersThatDoNotMatchItsOutputs) {
  EXPECT_NE(refusal("scatter", {{"by", "type"}, {"types", "rigid"}})
                .find("needs one type name in 'types' per output"),
            std::string::npos);
  EXPECT_NE(refusal("scatter", {{"by", "bounds"}, {"cuts", "1, 2"}}).find("needs N-1 numbers"),
            std::string::npos);
  EXPECT_NE(refusal("scatter", {{"cuts", "1"}}).find("applies only with by=\"bounds\""),
            std::string::npos);
  EXPECT_NE(refusal("scatter", {{"outputs", "3"}, {"by", "bounds"}, {"cuts", "2, 1"}})
                .find("strictly increasing"),
            std::string::npos);
}

TEST(RouteFilter, SendsEachReceiverTheObjectsItsVolumeMeets) {
  auto h = harness("route", {{"outputs", "2"}});
  ASSERT_TRUE(h);
  const auto interest = [&](const char* volume) {
    return h->message([&](msg::MessageBuilder& b) { b.addStringStamp("interest", volume); });
  };
  h->push("interest0", interest("-1 -1 -1 1 1 1"));
  h->push("interest1", interest("4 4 4 6 6 6"));
  h->push("in", pointsAt(*h, 3, {0.5, 5, 9}));
  h->step();
  const auto near = h->take("out0");
  const auto far = h->take("out1");
  ASSERT_EQ(near.size(), 1u);
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(idsOf(near[0]), (std::vector<uint64_t>{100}));
  EXPECT_EQ(idsOf(far[0]), (std::vector<uint64_t>{101}));
  EXPECT_EQ(far[0].view()->stamps().iteration, 3u);
}

// lockstep: message k of `in` waits for k interest messages from each receiver whose input is
// open, so a receiver's answer to message k-1 applies to message k even when it arrives after
// message k (another host's path); without lockstep message k is routed with what has come.
TEST(RouteFilter, LockstepRoutesMessageKWithEachReceiversAnswerToMessageKMinusOne) {
  for (const bool lockstep : {false, true}) {
    SCOPED_TRACE(lockstep ? "lockstep" : "latest volume");
    auto h = harness("route", {{"outputs", "2"}, {"lockstep", lockstep ? "true" : "false"}});
    ASSERT_TRUE(h);
    const auto interest = [&](const char* volume) {
      return h->message([&](msg::MessageBuilder& b) { b.addStringStamp("interest", volume); });
    };
    h->push("in", pointsAt(*h, 0, {0.5, 5}));  // message 0: no volume yet, nothing to wait for
    h->step();
    ASSERT_EQ(h->take("out0").size(), 1u);
    ASSERT_EQ(h->take("out1").size(), 1u);
    h->push("in", pointsAt(*h, 1, {0.5, 5}));  // message 1 comes before the answers to 0
    h->push("interest1", interest("4 4 4 6 6 6"));
    h->step();
    auto near = h->take("out0");
    auto far = h->take("out1");
    if (!lockstep) {
      ASSERT_EQ(near.size(), 1u);
      EXPECT_TRUE(idsOf(near[0]).empty());  // receiver 0's volume was still on its way
      continue;
    }
    EXPECT_TRUE(near.empty());  // waits for receiver 0's answer
    EXPECT_TRUE(far.empty());
    h->push("interest0", interest("-1 -1 -1 1 1 1"));
    h->step();
    near = h->take("out0");
    far = h->take("out1");
    ASSERT_EQ(near.size(), 1u);
    ASSERT_EQ(far.size(), 1u);
    EXPECT_EQ(idsOf(near[0]), (std::vector<uint64_t>{100}));
    EXPECT_EQ(idsOf(far[0]), (std::vector<uint64_t>{101}));
    // A receiver whose interest input ended is not waited for: its volume stays.
    h->close("interest1");
    h->push("in", pointsAt(*h, 2, {0.5, 5}));
    h->push("interest0", interest("-1 -1 -1 1 1 1"));
    h->step();
    far = h->take("out1");
    ASSERT_EQ(h->take("out0").size(), 1u);
    ASSERT_EQ(far.size(), 1u);
    EXPECT_EQ(idsOf(far[0]), (std::vector<uint64_t>{101}));
  }
}

TEST(RouteFilter, RefusesAnEmptyStampName) {
  EXPECT_NE(refusal("route", {{"stamp", ""}}).find("must name a user stamp"), std::string::npos);
  EXPECT_NE(refusal("route", {{"initially", "some"}}), "");
}

}  // namespace
}  // namespace vrflow::testing
