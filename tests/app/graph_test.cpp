#include "vrflow/app/graph.hpp"

#include <gtest/gtest.h>

#include <map>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"

namespace vrflow::app {
namespace {

TEST(ResolvedGraph, GroupsConnectionsByPortInFileOrder) {
  const Result<Application> app = loadApplicationFile(testing::dataDir() + "/valid_cluster.xml");
  ASSERT_TRUE(app.ok()) << app.error().message;
  const ResolvedGraph graph = resolveGraph(*app);

  ASSERT_EQ(graph.inputs.size(), 6u);
  EXPECT_EQ(graph.inputs[0].node, "join");
  EXPECT_EQ(graph.inputs[0].port, "in0");
  const PortEdges* relayIn = graph.findInput("relay", "in");
  ASSERT_NE(relayIn, nullptr);
  EXPECT_EQ(relayIn->connections, (std::vector<std::size_t>{4}));
  EXPECT_EQ(relayIn->initialMessages, 2);
  EXPECT_EQ(graph.findInput("relay", "beginIt")->initialMessages, 1);
  EXPECT_EQ(graph.findInput("sink", "in")->mode, InputMode::Latest);
  EXPECT_EQ(graph.findInput("sink", "in")->initialMessages, 0);

  const PortEdges* fanout = graph.findOutput("fanout", "out");
  ASSERT_NE(fanout, nullptr);
  EXPECT_EQ(fanout->connections, (std::vector<std::size_t>{3, 4}));
  EXPECT_EQ(graph.outputsOf("sink").size(), 1u);
  EXPECT_EQ(graph.inputsOf("relay").size(), 2u);
  EXPECT_EQ(graph.findInput("left", "in"), nullptr);
}

TEST(ResolvedGraph, SeveralConnectionsIntoOneInputKeepFileOrder) {
  Application app;
  for (const char* id : {"a", "b", "c"}) {
    Module module;
    module.id = id;
    app.modules.push_back(module);
  }
  app.connections = {Connection{{"b", "out"}, {"c", "in"}, 0, QueuePolicy::Block, {}},
                     Connection{{"a", "out"}, {"c", "in"}, 0, QueuePolicy::Block, {}}};
  const ResolvedGraph graph = resolveGraph(app);
  ASSERT_EQ(graph.inputs.size(), 1u);
  EXPECT_EQ(graph.inputs[0].connections, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(graph.outputs.size(), 2u);
}

// ---- iteration rates (multi-rate) ---------------------------------------------------------

struct RateApp {
  Application app;
  void module(const std::string& id) {
    Module m;
    m.id = id;
    app.modules.push_back(m);
  }
  void filter(const std::string& id, const std::string& type, const std::string& count = "") {
    Filter f;
    f.id = id;
    f.type = type;
    if (!count.empty()) f.params.push_back({"count", count, {}});
    app.filters.push_back(f);
  }
  void connect(const std::string& from, const std::string& to) {
    app.connections.push_back(Connection{{from, "out"}, {to, "in"}, 0, QueuePolicy::Block, {}});
  }
  std::map<std::string, std::pair<uint64_t, uint64_t>> rates() const {
    const auto all = iterationRates(app, resolveGraph(app));
    std::map<std::string, std::pair<uint64_t, uint64_t>> byId;
    for (std::size_t i = 0; i < all.size(); ++i) {
      byId[app.modules[i].id] = {all[i].numerator, all[i].denominator};
    }
    return byId;
  }
};

// The demo scene's net at 10x: clock -> repeat(10) -> net <-> springs (a cycle), net ->
// decimate(10) -> contacts (beside the clock's own output).
TEST(IterationRates, RepeatMultipliesDecimateDividesAndCyclesSettle) {
  RateApp r;
  for (const char* id : {"clock", "net", "springs", "contacts", "log"}) r.module(id);
  r.filter("ten", "repeat", "10");
  r.filter("last", "decimate", "10");
  r.connect("clock", "ten");
  r.connect("ten", "net");
  r.connect("springs", "net");
  r.connect("net", "springs");
  r.connect("net", "last");
  r.connect("last", "contacts");
  r.connect("clock", "contacts");
  r.connect("last", "log");
  const auto rates = r.rates();
  using R = std::pair<uint64_t, uint64_t>;
  EXPECT_EQ(rates.at("clock"), R(1, 1));
  EXPECT_EQ(rates.at("net"), R(10, 1));
  EXPECT_EQ(rates.at("springs"), R(10, 1));
  EXPECT_EQ(rates.at("contacts"), R(1, 1));
  EXPECT_EQ(rates.at("log"), R(1, 1));
  const auto all = iterationRates(r.app, resolveGraph(r.app));
  EXPECT_EQ(all[1].scale(300), 3000u);
  EXPECT_EQ(all[0].scale(0), 0u);
}

// The demo scene at 10x: no source, every animator waits on its interactors. Whichever module
// comes first in the file, the slowest runs once per outer iteration.
TEST(IterationRates, AClosedLoopIsScaledToItsSlowestModule) {
  for (const bool netFirst : {true, false}) {
    RateApp r;
    if (netFirst) r.module("net");
    for (const char* id : {"bodies", "contacts", "netcontacts", "springs"}) r.module(id);
    if (!netFirst) r.module("net");
    r.filter("ten", "repeat", "10");
    r.filter("last", "decimate", "10");
    r.connect("bodies", "contacts");
    r.connect("contacts", "bodies");
    r.connect("bodies", "netcontacts");
    r.connect("netcontacts", "bodies");
    r.connect("net", "last");
    r.connect("last", "netcontacts");
    r.connect("netcontacts", "ten");
    r.connect("ten", "net");
    r.connect("net", "springs");
    r.connect("springs", "net");
    const auto rates = r.rates();
    using R = std::pair<uint64_t, uint64_t>;
    EXPECT_EQ(rates.at("bodies"), R(1, 1)) << netFirst;
    EXPECT_EQ(rates.at("contacts"), R(1, 1)) << netFirst;
    EXPECT_EQ(rates.at("netcontacts"), R(1, 1)) << netFirst;
    EXPECT_EQ(rates.at("net"), R(10, 1)) << netFirst;
    EXPECT_EQ(rates.at("springs"), R(10, 1)) << netFirst;
  }
}

TEST(IterationRates, DecimateAloneSlowsAndRoundsUpAndTheDefaultCountIsTen) {
  RateApp r;
  r.module("fast");
  r.module("slow");
  r.filter("third", "decimate", "3");
  r.filter("tenth", "decimate");
  r.module("slowest");
  r.connect("fast", "third");
  r.connect("third", "slow");
  r.connect("fast", "tenth");
  r.connect("tenth", "slowest");
  const auto all = iterationRates(r.app, resolveGraph(r.app));
  EXPECT_EQ(all[1], (IterationRate{1, 3}));
  EXPECT_EQ(all[1].scale(100), 34u);
  EXPECT_EQ(all[2], (IterationRate{1, 10}));
  EXPECT_EQ(all[2].scale(5), 1u) << "at least one iteration";
}

TEST(IterationRates, AGrowingCycleOrAnIsolatedCycleFallsBackToOne) {
  RateApp grow;
  grow.module("a");
  grow.module("b");
  grow.filter("more", "repeat", "2");
  grow.connect("a", "more");
  grow.connect("more", "b");
  grow.connect("b", "a");
  for (const auto& rate : iterationRates(grow.app, resolveGraph(grow.app))) {
    EXPECT_EQ(rate, IterationRate{});
  }
  RateApp loop;
  loop.module("ping");
  loop.module("pong");
  loop.connect("ping", "pong");
  loop.connect("pong", "ping");
  for (const auto& rate : iterationRates(loop.app, resolveGraph(loop.app))) {
    EXPECT_EQ(rate, IterationRate{});
  }
}

}  // namespace
}  // namespace vrflow::app
