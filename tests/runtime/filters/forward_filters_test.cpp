// The forwarding and joining filters run in-process (FilterHarness): passthrough, broadcast,
// initial, merge, gather; and the filter test harness itself.
#include <gtest/gtest.h>

#include "harness_support.hpp"
#include "vrflow/daemon/filter_registry.hpp"
#include "vrflow/message/builtin_types.hpp"

namespace vrflow::testing {
namespace {

using Iterations = std::vector<uint64_t>;

// A message holding `points` point objects, with iteration stamp `iteration`.
daemon::MessageRef points(FilterHarness& h, uint64_t iteration, int count) {
  return h.message([&](msg::MessageBuilder& builder) {
    builder.setIteration(iteration);
    for (int i = 0; i < count; ++i) {
      builder.addObject(static_cast<uint64_t>(100 + i), msg::pointType())
          .set(msg::PointParam::kPosition, msg::Vec3{1.0 * i, 0, 0});
    }
  });
}

TEST(FilterHarness, RefusesAnUnknownTypeOrParameterAsValidationDoes) {
  EXPECT_EQ(refusal("no-such-filter", {}), "unknown filter type 'no-such-filter'");
  EXPECT_EQ(refusal("gate", {{"colour", "red"}}), "filter type 'gate' has no parameter 'colour'");
  EXPECT_NE(refusal("rotate", {{"outputs", "many"}})
                .find("parameter 'outputs' of filter type "
                      "'rotate' expects an int"),
            std::string::npos)
      << refusal("rotate", {{"outputs", "many"}});
}

TEST(FilterHarness, GivesTheFilterThePortsItsDeclarationListsForItsParameters) {
  auto h = harness("merge", {{"inputs", "3"}});
  ASSERT_TRUE(h);
  EXPECT_EQ(h->inputNames(), (std::vector<std::string>{"in0", "in1", "in2"}));
  EXPECT_EQ(h->outputNames(), (std::vector<std::string>{"out"}));
  EXPECT_EQ(h->params().getString("stamps"), "");  // the declared default
}

TEST(FilterRegistry, TheCatalogListsEveryTypeOfTheRegistryButThePortFilters) {
  const app::Catalog catalog = daemon::makeCatalog();
  std::vector<std::string> listed;
  for (const app::FilterType* type : catalog.filterTypes()) listed.push_back(type->name);
  std::vector<std::string> registered = daemon::FilterRegistry::instance().types();
  std::erase(registered, "port-input");
  std::erase(registered, "port-output");
  EXPECT_EQ(listed, registered);
  EXPECT_EQ(catalog.findFilter("port-input"), nullptr);
  EXPECT_TRUE(app::Catalog().filterTypes().empty());  // the app layer declares none itself
}

TEST(PassthroughFilter, ForwardsInOrderAndHoldsWhatTheOutputCannotTake) {
  for (const char* type : {"passthrough", "broadcast"}) {
    auto h = harness(type);
    ASSERT_TRUE(h);
    for (uint64_t i = 0; i < 3; ++i) h->push("in", h->stamped(i));
    h->setRoom("out", 2);
    h->step();
    EXPECT_EQ(h->takeIterations("out"), (Iterations{0, 1})) << type;
    h->setRoom("out", 5);
    h->step();
    EXPECT_EQ(h->takeIterations("out"), (Iterations{2})) << type;
    EXPECT_FALSE(h->exhausted());
    h->close("in");
    EXPECT_TRUE(h->exhausted());
  }
}

TEST(InitialFilter, EmitsAsManyEmptyMessagesAsItsDeclarationSaysThenForwards) {
  const app::FilterType& declared = daemon::FilterRegistry::instance().find("initial")->declaration;
  for (const Params& params : {Params{}, Params{{"count", "3"}}, Params{{"count", "0"}}}) {
    std::vector<app::Param> values;
    for (const auto& [name, value] : params) values.push_back(app::Param{name, value, {}});
    auto h = harness("initial", params);
    ASSERT_TRUE(h);
    h->step();
    const auto emitted = h->take("out");
    EXPECT_EQ(emitted.size(), static_cast<std::size_t>(declared.initialMessagesFor(values)));
    for (const auto& message : emitted) EXPECT_EQ(chunksOf(message), 0u);
    h->push("in", h->stamped(7));
    h->step();
    EXPECT_EQ(h->takeIterations("out"), (Iterations{7}));
  }
  EXPECT_EQ(declared.initialMessagesFor({}), 1);
}

TEST(InitialFilter, RefusesANegativeOrHugeCount) {
  EXPECT_NE(refusal("initial", {{"count", "-1"}}).find("below its minimum 0"), std::string::npos);
  EXPECT_NE(refusal("initial", {{"count", "1000001"}}).find("above its maximum"),
            std::string::npos);
}

TEST(MergeFilter, WaitsForEveryInputThenEmitsTheirChunksWithTheLargestIteration) {
  auto h = harness("merge", {{"inputs", "3"}});
  ASSERT_TRUE(h);
  h->push("in0", points(*h, 4, 1));
  h->push("in1", points(*h, 9, 2));
  h->step();
  EXPECT_TRUE(h->take("out").empty());
  h->push("in2", points(*h, 5, 3));
  h->step();
  const auto out = h->take("out");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(chunksOf(out[0]), 6u);
  EXPECT_EQ(out[0].view()->stamps().iteration, 9u);
}

TEST(MergeFilter, CombinesUserStampsByItsRules) {
  auto h = harness("gather", {{"inputs", "2"}, {"stamps", "n:sum"}});
  ASSERT_TRUE(h);
  for (const char* port : {"in0", "in1"}) {
    h->push(port, h->message([&](msg::MessageBuilder& b) { b.addInt64Stamp("n", 20); }));
  }
  h->step();
  const auto out = h->take("out");
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].view()->stamps().user.find("n")->asInt64(), 40);
}

TEST(MergeFilter, RefusesAnUnknownStampRule) {
  EXPECT_NE(refusal("merge", {{"stamps", "n:average"}}).find("filter type 'merge': "),
            std::string::npos);
  EXPECT_NE(refusal("gather", {{"inputs", "0"}}).find("below its minimum 1"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::testing
