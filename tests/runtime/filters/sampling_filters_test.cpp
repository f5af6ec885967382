// The sampling, selecting and multi-rate filters run in-process (FilterHarness): latest,
// maxfrequency, stampfilter, typefilter, repeat, decimate.
#include <gtest/gtest.h>

#include "harness_support.hpp"
#include "vrflow/message/builtin_types.hpp"

namespace vrflow::testing {
namespace {

using Iterations = std::vector<uint64_t>;
constexpr uint64_t kMs = 1'000'000;

TEST(LatestFilter, ForwardsOnlyTheNewestMessageOncePerSync) {
  auto h = harness("latest");
  ASSERT_TRUE(h);
  for (uint64_t i = 1; i <= 3; ++i) h->push("in", h->stamped(i));
  h->step();  // the initial sync
  EXPECT_EQ(h->takeIterations("out"), (Iterations{3}));
  EXPECT_EQ(h->droppedOn("in"), 2u);
  h->push("in", h->stamped(4));
  h->step();
  EXPECT_TRUE(h->take("out").empty());  // no sync yet
  h->push("sync", h->message());
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{4}));
  h->push("sync", h->message());
  h->step();
  EXPECT_TRUE(h->take("out").empty());  // nothing newer: the sync waits
  h->push("in", h->stamped(5));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{5}));
}

TEST(LatestFilter, RepeatsTheLastMessageWhenAskedAndRefusesANegativeInitialSync) {
  auto h = harness("latest", {{"repeat", "true"}, {"initial-sync", "0"}});
  ASSERT_TRUE(h);
  h->push("in", h->stamped(8));
  h->push("sync", h->message());
  h->push("sync", h->message());
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{8, 8}));
  EXPECT_NE(refusal("latest", {{"initial-sync", "-1"}}).find("below its minimum 0"),
            std::string::npos);
}

TEST(MaxFrequencyFilter, SpacesMessagesByThePeriodOnItsTimer) {
  auto h = harness("maxfrequency", {{"frequency", "10"}});
  ASSERT_TRUE(h);
  h->push("in", h->stamped(1));
  h->push("in", h->stamped(2));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{1}));
  EXPECT_EQ(h->wakeDelay(), 100 * kMs);
  h->advanceClock(60 * kMs);
  h->step();
  EXPECT_TRUE(h->take("out").empty());
  EXPECT_EQ(h->wakeDelay(), 40 * kMs);
  h->advanceClock(40 * kMs);
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{2}));
}

TEST(MaxFrequencyFilter, KeepsOnlyTheNewestInLatestModeAndRefusesAZeroFrequency) {
  auto h = harness("maxfrequency", {{"mode", "latest"}});
  ASSERT_TRUE(h);
  for (uint64_t i = 1; i <= 3; ++i) h->push("in", h->stamped(i));
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{3}));
  EXPECT_EQ(h->droppedOn("in"), 2u);
  EXPECT_NE(refusal("maxfrequency", {{"frequency", "0"}}).find("below its minimum"),
            std::string::npos);
  EXPECT_NE(refusal("maxfrequency", {{"mode", "fast"}}), "");
}

TEST(StampFilter, ForwardsTheMessageEachOrderNamesAndDropsOlderOnes) {
  auto h = harness("stampfilter");
  ASSERT_TRUE(h);
  for (uint64_t i = 1; i <= 4; ++i) h->push("in", h->stamped(i));
  h->push("order", h->message([](msg::MessageBuilder& b) { b.addInt64Stamp("iteration", 2); }));
  h->push("order", h->stamped(4));  // no user stamp: its own iteration
  h->step();
  EXPECT_EQ(h->takeIterations("out"), (Iterations{2, 4}));
  EXPECT_EQ(h->droppedOn("in"), 2u);  // 1 and 3 can never be ordered any more
}

TEST(TypeFilter, KeepsOnlyTheListedObjectTypes) {
  auto h = harness("typefilter", {{"types", "point"}});
  ASSERT_TRUE(h);
  h->push("in", h->message([](msg::MessageBuilder& b) {
    b.setIteration(6);
    b.addObject(1, msg::rigidType()).set(msg::RigidParam::kMass, 2.0);
    b.addObject(2, msg::pointType()).set(msg::PointParam::kMass, 1.0);
  }));
  h->step();
  const auto out = h->take("out");
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(chunksOf(out[0]), 1u);
  EXPECT_EQ((*out[0].view()->begin()).id(), 2u);
  EXPECT_EQ(out[0].view()->stamps().iteration, 6u);
}

TEST(TypeFilter, RefusesAnEmptyTypeList) {
  EXPECT_NE(refusal("typefilter", {}).find("must list at least one object type name"),
            std::string::npos);
  EXPECT_NE(refusal("typefilter", {{"types", "point"}, {"drop-others", "maybe"}}), "");
}

TEST(RepeatFilter, SendsEachMessageCountTimesOnSubSteps) {
  auto h = harness("repeat", {{"count", "4"}});
  ASSERT_TRUE(h);
  h->push("in", h->message([](msg::MessageBuilder& b) {
    b.setIteration(2);
    b.setSimTime(1.0);
    b.setTimeStep(0.5);
  }));
  h->step();
  const auto out = h->take("out");
  ASSERT_EQ(out.size(), 4u);
  for (std::size_t j = 0; j < out.size(); ++j) {
    const auto stamps = out[j].view()->stamps();
    EXPECT_EQ(stamps.iteration, 8 + j);
    EXPECT_DOUBLE_EQ(stamps.timeStep, 0.125);
    EXPECT_DOUBLE_EQ(stamps.simTime, 1.0 + 0.125 * static_cast<double>(j));
  }
  EXPECT_NE(refusal("repeat", {{"count", "0"}}).find("below its minimum 1"), std::string::npos);
}

TEST(DecimateFilter, ForwardsTheLastOfEachGroupRestamped) {
  auto h = harness("decimate", {{"count", "3"}});
  ASSERT_TRUE(h);
  for (uint64_t i = 10; i < 17; ++i) {
    h->push("in", h->message([&](msg::MessageBuilder& b) {
      b.setIteration(i);
      b.setTimeStep(0.25);
    }));
  }
  h->step();
  const auto out = h->take("out");
  ASSERT_EQ(out.size(), 2u);  // 10-12 and 13-15; 16 waits for its group
  for (std::size_t g = 0; g < out.size(); ++g) {
    EXPECT_EQ(out[g].view()->stamps().iteration, g);
    EXPECT_DOUBLE_EQ(out[g].view()->stamps().timeStep, 0.75);
  }

  auto untouched = harness("decimate", {{"count", "2"}, {"restamp", "false"}, {"merge", "false"}});
  ASSERT_TRUE(untouched);
  for (uint64_t i = 10; i < 14; ++i) untouched->push("in", untouched->stamped(i));
  untouched->step();
  EXPECT_EQ(untouched->takeIterations("out"), (Iterations{11, 13}));
  EXPECT_EQ(untouched->droppedOn("in"), 2u);
  EXPECT_NE(refusal("decimate", {{"count", "-2"}}).find("below its minimum 1"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::testing
