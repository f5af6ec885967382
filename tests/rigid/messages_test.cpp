// Rigid bodies through messages: what the animator writes is what an interactor's copy reads.
#include "vrflow/rigid/messages.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/rigid/scene.hpp"

namespace vrflow::rigid {
namespace {

TEST(RigidMessages, AddThenUpdateRoundTripsThroughTheCopy) {
  auto bodies = generateScene("mixed:4");
  ASSERT_TRUE(bodies);
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  for (const Body& b : *bodies) writeAdd(builder, b, 1000 + b.id);
  const auto size = builder.finish();
  auto view = msg::MessageView::parse(std::span(sink.buffer()).first(size));
  ASSERT_TRUE(view) << view.error().message;
  RigidObjectCopy copy;
  ASSERT_TRUE(copy.apply(*view));
  ASSERT_EQ(copy.entries().size(), bodies->size());
  for (const Body& b : *bodies) {
    const auto& e = copy.entries().at(b.id);
    EXPECT_TRUE(e.hasShape);
    EXPECT_TRUE(e.shapeChanged);
    EXPECT_TRUE(e.stateChanged);
    EXPECT_EQ(e.body.shape, b.shape);
    EXPECT_EQ(e.body.kinematic, b.kinematic);
    EXPECT_EQ(e.body.position, b.position);
    EXPECT_EQ(e.body.orientation, b.orientation);
    if (!b.kinematic) {
      EXPECT_EQ(e.body.mass, b.mass);
      EXPECT_EQ(e.body.inertia, b.inertia);
    }
  }
  // An update carries only what changed.
  Body moved = (*bodies).back();
  moved.position[1] += 1;
  msg::VectorSink sink2;
  msg::MessageBuilder update(sink2);
  writeUpdate(update, moved, Change{moved.id, true, false});
  const auto size2 = update.finish();
  auto view2 = msg::MessageView::parse(std::span(sink2.buffer()).first(size2));
  ASSERT_TRUE(view2);
  const auto object = (*view2->begin()).asObject();
  ASSERT_TRUE(object);
  EXPECT_TRUE(object->vec3(msg::RigidParam::kPosition));
  EXPECT_TRUE(object->aabb(msg::RigidParam::kBounds));
  EXPECT_FALSE(object->vec3(msg::RigidParam::kLinearVelocity));
  EXPECT_FALSE(object->scalar(msg::RigidParam::kMass));
  for (auto& [id, entry] : copy.entries()) entry.stateChanged = false;
  ASSERT_TRUE(copy.apply(*view2));
  EXPECT_EQ(copy.entries().at(moved.id).body.position, moved.position);
  // Only the updated body is flagged: a reader refreshes its own copy of that one only.
  for (const auto& [id, entry] : copy.entries())
    EXPECT_EQ(entry.stateChanged, id == moved.id) << "body " << id;
}

TEST(RigidMessages, MaterialsTravelOnlyWhenABodyHasItsOwn) {
  Body plain = makeBody(1, msg::Shape::sphere(0.1), 1.0, {0, 0, 0});
  Body rubber = makeBody(2, msg::Shape::sphere(0.1), 1.0, {1, 0, 0});
  rubber.friction = 0.9;
  rubber.restitution = 0.8;
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  writeAdd(builder, plain, 11);
  writeAdd(builder, rubber, 12);
  const auto size = builder.finish();
  auto view = msg::MessageView::parse(std::span(sink.buffer()).first(size));
  ASSERT_TRUE(view) << view.error().message;
  for (const auto chunk : *view) {
    const auto object = chunk.asObject();
    if (!object) continue;
    EXPECT_EQ(object->scalar(msg::RigidParam::kFriction).has_value(), object->id() == 2);
  }
  RigidObjectCopy copy;
  ASSERT_TRUE(copy.apply(*view));
  EXPECT_LT(copy.entries().at(1).body.friction, 0.0);
  EXPECT_EQ(copy.entries().at(2).body.friction, 0.9);
  EXPECT_EQ(copy.entries().at(2).body.restitution, 0.8);
}

TEST(RigidMessages, ObjectNamingAMissingShapeIsAnError) {
  msg::VectorSink sink;
  msg::MessageBuilder builder(sink);
  builder.addObject(5, msg::rigidType(), msg::ObjectOp::Add)
      .set(msg::RigidParam::kShape, std::uint64_t{77});
  const auto size = builder.finish();
  auto view = msg::MessageView::parse(std::span(sink.buffer()).first(size));
  ASSERT_TRUE(view);
  RigidObjectCopy copy;
  const auto status = copy.apply(*view);
  ASSERT_FALSE(status);
  EXPECT_NE(status.error().message.find("77"), std::string::npos);
}

}  // namespace
}  // namespace vrflow::rigid
