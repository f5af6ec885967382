#include "vrflow/app/graph.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace vrflow::app
