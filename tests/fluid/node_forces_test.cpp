#include "node_forces.hpp"

#include <gtest/gtest.h>

#include "tank.hpp"
#include "vrflow/massspring/events.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/reader.hpp"

// The fluid module's node forces, read back with the massspring package's own decoder: the
// format the net animator applies.
namespace vrflow::fluid {
namespace {

TEST(FluidNodeForces, SubmergedNodesForceReachesTheNetInTheMassspringFormat) {
  auto tank = testing::makeTank(testing::smallTank(12, 12, 12), 0.45);
  std::vector<PointMass> nodes(2);
  nodes[0].id = 77;
  nodes[0].index = 5;
  nodes[0].position = {0.3, 0.2, 0.3};  // under water
  nodes[0].radius = 0.06;
  nodes[1].id = 77;
  nodes[1].index = 6;
  nodes[1].position = {0.3, 0.2, 0.9};
  nodes[1].radius = 0.06;  // outside the grid: gets no record
  auto forces = tank->step(0.01, {}, nodes);
  ASSERT_TRUE(forces.ok());
  ASSERT_EQ(forces->size(), 2u);

  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  EXPECT_EQ(addNodeForceEvents(builder, nodes, *forces), 1);
  const auto size = builder.finish();
  ASSERT_GT(size, 0u);
  auto view = msg::MessageView::parse(builder.bytes());
  ASSERT_TRUE(view.ok()) << view.error().message;
  int events = 0;
  for (const auto chunk : *view) {
    auto event = chunk.asEvent();
    ASSERT_TRUE(event);
    EXPECT_EQ(event->id(), 77u);
    EXPECT_EQ(event->kind(), massspring::kNodeForcesEvent);
    auto decoded = massspring::decodeNodeForces(event->payload());
    ASSERT_TRUE(decoded.ok()) << decoded.error().message;
    ASSERT_EQ(decoded->size(), 1u);
    EXPECT_EQ((*decoded)[0].node, 5u);
    EXPECT_EQ((*decoded)[0].force, (*forces)[0].force);
    EXPECT_GT((*decoded)[0].force[1], 0.0);  // buoyancy
    ++events;
  }
  EXPECT_EQ(events, 1);
}

}  // namespace
}  // namespace vrflow::fluid
