#include <gtest/gtest.h>

#include <vector>

#include "allocation_counter.hpp"
#include "sample_messages.hpp"
#include "vrflow/message/empty_message.hpp"

namespace vrflow::msg {
namespace {

using testing::finished;
using testing::sampleMessage;
using testing::sampleStamps;
using testing::toBytes;

std::vector<ChunkView> chunksOf(const MessageView& view) {
  std::vector<ChunkView> chunks;
  for (const ChunkView chunk : view) chunks.push_back(chunk);
  return chunks;
}

TEST(RoundTrip, StampsComeBackAsWritten) {
  const auto bytes = sampleMessage();
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  const StampsView stamps = view->stamps();
  EXPECT_EQ(stamps.source, "rigid-animator");
  EXPECT_EQ(stamps.iteration, 42u);
  EXPECT_EQ(stamps.simTime, 1.25);
  EXPECT_EQ(stamps.timeStep, 0.01);
  EXPECT_EQ(stamps.sendTimeNs, 1'700'000'000'123'456'789ull);
  ASSERT_EQ(stamps.user.size(), 3u);
  EXPECT_EQ(stamps.user.find("frame")->asInt64(), -7);
  EXPECT_EQ(stamps.user.find("gain")->asDouble(), 0.5);
  EXPECT_EQ(stamps.user.find("camera")->asString(), "left");
  EXPECT_FALSE(stamps.user.find("camera")->asInt64().has_value());
  EXPECT_FALSE(stamps.user.find("missing").has_value());
  EXPECT_EQ(stamps.toStamps(), sampleStamps());
  EXPECT_EQ(view->version(), kLayoutVersion);
  EXPECT_FALSE(view->stampsOnly());
}

TEST(RoundTrip, EveryChunkKindComesBackAsWritten) {
  const auto bytes = sampleMessage();
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  ASSERT_EQ(view->chunkCount(), 9u);
  const auto chunks = chunksOf(*view);
  ASSERT_EQ(chunks.size(), 9u);
  for (const ChunkView& chunk : chunks) EXPECT_EQ(chunk.offset() % 8, 0u);

  // Added rigid body: only the five parameters set travel.
  const auto rigid = chunks[0].asObject();
  ASSERT_TRUE(rigid.has_value());
  EXPECT_EQ(rigid->op(), ObjectOp::Add);
  EXPECT_EQ(rigid->id(), makeId(0x0A000001u, 1));
  EXPECT_EQ(rigid->typeId(), rigidType().id());
  ASSERT_NE(rigid->type(), nullptr);
  EXPECT_EQ(rigid->type()->name(), "rigid");
  EXPECT_EQ(rigid->vec3(RigidParam::kPosition), (Vec3{1.0, 2.0, 3.0}));
  EXPECT_EQ(rigid->quat(RigidParam::kOrientation), (Quat{0.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(rigid->scalar(RigidParam::kMass), 2.5);
  EXPECT_EQ(rigid->aabb(RigidParam::kBounds), (Aabb{{-1, -1, -1}, {1, 1, 1}}));
  EXPECT_EQ(rigid->idParam(RigidParam::kShape), makeId(0x0A000001u, 3));
  EXPECT_FALSE(rigid->vec3(RigidParam::kLinearVelocity).has_value());
  EXPECT_FALSE(rigid->scalar(RigidParam::kPosition).has_value());  // wrong size for a Scalar
  EXPECT_FALSE(chunks[0].asResource().has_value());

  const auto point = chunks[1].asObject();
  ASSERT_TRUE(point.has_value());
  EXPECT_EQ(point->op(), ObjectOp::Update);
  EXPECT_EQ(point->mask(), std::uint64_t{1} << PointParam::kVelocity);
  EXPECT_EQ(point->vec3(PointParam::kVelocity), (Vec3{0.0, -9.81, 0.0}));

  const auto removed = chunks[2].asObject();
  ASSERT_TRUE(removed.has_value());
  EXPECT_EQ(removed->op(), ObjectOp::Delete);
  EXPECT_EQ(removed->id(), makeId(0x0A000002u, 9));
  EXPECT_EQ(removed->mask(), 0u);
  EXPECT_TRUE(chunks[2].body().empty());

  const auto raw = chunks[3].asResource();
  ASSERT_TRUE(raw.has_value());
  EXPECT_EQ(raw->kind(), ResourceKind::Raw);
  EXPECT_FALSE(raw->dynamic());
  const auto text = toBytes("thirteen-byte");
  EXPECT_TRUE(std::equal(raw->raw().begin(), raw->raw().end(), text.begin(), text.end()));
  EXPECT_FALSE(raw->mesh().has_value());

  const auto mesh = chunks[4].asResource()->mesh();
  ASSERT_TRUE(mesh.has_value());
  EXPECT_EQ(mesh->vertexCount(), 4u);
  EXPECT_EQ(mesh->triangleCount(), 2u);
  EXPECT_EQ(mesh->vertex(1), (std::array<float, 3>{1, 0, 0}));
  const std::vector<std::uint32_t> indices(mesh->indices().begin(), mesh->indices().end());
  EXPECT_EQ(indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  std::vector<float> xyz(mesh->xyz().size());
  mesh->xyz().copyTo(xyz);
  EXPECT_EQ(xyz[10], 0.0f);
  EXPECT_EQ(xyz[11], 1.0f);

  const auto scalarField = chunks[5].asResource();
  EXPECT_TRUE(scalarField->dynamic());
  EXPECT_EQ(scalarField->kind(), ResourceKind::ScalarField);
  const auto scalars = scalarField->field();
  ASSERT_TRUE(scalars.has_value());
  EXPECT_EQ(scalars->dims(), (std::array<std::uint32_t, 3>{2, 2, 2}));
  EXPECT_EQ(scalars->components(), 1u);
  EXPECT_EQ(scalars->spacing(), 0.5);
  ASSERT_EQ(scalars->data().size(), 8u);
  EXPECT_EQ(scalars->data()[7], 8.0f);

  const auto vectors = chunks[6].asResource()->field();
  ASSERT_TRUE(vectors.has_value());
  EXPECT_EQ(chunks[6].asResource()->kind(), ResourceKind::VectorField);
  EXPECT_EQ(vectors->components(), 3u);
  EXPECT_EQ(vectors->origin(), (Vec3{-1, 0, 0}));
  EXPECT_EQ(vectors->data()[4], 1.0f);

  const auto force = chunks[7].asEvent();
  ASSERT_TRUE(force.has_value());
  EXPECT_TRUE(force->isForce());
  EXPECT_EQ(force->id(), makeId(0x0A000001u, 1));
  EXPECT_EQ(force->force(), (ForceEvent{{0, 10, 0}, {0, 0, 1}, {0.5, 0.5, 0.5}, 0.02}));

  const auto user = chunks[8].asEvent();
  ASSERT_TRUE(user.has_value());
  EXPECT_EQ(user->kind(), 2000);
  EXPECT_FALSE(user->force().has_value());
  const auto select = toBytes("select");
  EXPECT_TRUE(
      std::equal(user->payload().begin(), user->payload().end(), select.begin(), select.end()));
}

TEST(RoundTrip, ArrayAndBytesParametersComeBackAsWritten) {
  VectorSink sink;
  MessageBuilder builder(sink);
  const std::vector<double> positions{0, 0, 0, 1, 1, 1};
  const std::vector<double> masses{1.0, 2.0};
  const std::vector<std::byte> pinned{std::byte{1}, std::byte{0}, std::byte{1}};
  builder.addObject(7, massSpringType(), ObjectOp::Add)
      .set("positions", positions)
      .set("masses", masses)
      .set("pinned", std::span<const std::byte>(pinned));
  auto gizmo = ObjectType::create("floaty", {{"samples", ParamKind::FloatArray},
                                             {"count", ParamKind::Int64},
                                             {"frame", ParamKind::Mat3}});
  ASSERT_TRUE(gizmo.ok());
  const std::vector<float> samples{0.5f, -0.25f, 3.0f};
  const Mat3 frame{1, 0, 0, 0, 1, 0, 0, 0, 1};
  builder.addObject(8, *gizmo, ObjectOp::Add)
      .set(0, samples)
      .set(1, std::int64_t{-3})
      .set(2, frame);
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  const auto chunks = chunksOf(*view);
  const auto net = chunks[0].asObject();
  const auto gotPositions = net->doubleArray(MassSpringParam::kPositions);
  ASSERT_TRUE(gotPositions.has_value());
  EXPECT_EQ(std::vector<double>(gotPositions->begin(), gotPositions->end()), positions);
  EXPECT_EQ(net->doubleArray(MassSpringParam::kMasses)->size(), 2u);
  const auto gotPinned = net->bytes(MassSpringParam::kPinned);
  ASSERT_TRUE(gotPinned.has_value());
  EXPECT_EQ(std::vector<std::byte>(gotPinned->begin(), gotPinned->end()), pinned);

  // "floaty" is not registered: the reader cannot check it, yet it stays readable.
  const auto floaty = chunks[1].asObject();
  EXPECT_EQ(floaty->type(), nullptr);
  const auto gotSamples = floaty->floatArray(0);
  ASSERT_TRUE(gotSamples.has_value());
  EXPECT_EQ(std::vector<float>(gotSamples->begin(), gotSamples->end()), samples);
  EXPECT_EQ(floaty->int64(1), -3);
  EXPECT_EQ(floaty->mat3(2), frame);
  std::vector<std::uint32_t> indices;
  for (const ParamEntry entry : floaty->params()) indices.push_back(entry.index);
  EXPECT_EQ(indices, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(RoundTrip, EmptyAndStampsOnlyMessagesHoldNoChunk) {
  const auto empty = makeEmptyMessage();
  ASSERT_EQ(empty.size(), kMessageHeaderSize);
  const auto emptyView = MessageView::parse(empty);
  ASSERT_TRUE(emptyView.ok()) << emptyView.error().message;
  EXPECT_EQ(emptyView->chunkCount(), 0u);
  EXPECT_FALSE(emptyView->stampsOnly());
  EXPECT_EQ(emptyView->begin(), emptyView->end());

  const auto signal = makeEmptyMessage(sampleStamps(), EmptyKind::StampsOnly);
  const auto signalView = MessageView::parse(signal);
  ASSERT_TRUE(signalView.ok()) << signalView.error().message;
  EXPECT_TRUE(signalView->stampsOnly());
  EXPECT_EQ(signalView->stamps().toStamps(), sampleStamps());
}

TEST(RoundTrip, DefaultViewReadsAsAnEmptyMessage) {
  const MessageView view;
  EXPECT_EQ(view.chunkCount(), 0u);
  EXPECT_EQ(view.begin(), view.end());
  EXPECT_EQ(view.stamps().source, "");
  EXPECT_TRUE(MessageView::parse(view.bytes()).ok());
}

TEST(RoundTrip, ParsingAndReadingAValidMessageAllocatesNothing) {
  const auto bytes = sampleMessage();
  ASSERT_TRUE(MessageView::parse(bytes).ok());  // first use initialises the global registry
  testing::AllocationCounter allocations;
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok());
  double sum = 0;
  for (const ChunkView chunk : *view) {
    if (const auto object = chunk.asObject()) {
      for (const ParamEntry entry : object->params())
        sum += static_cast<double>(entry.bytes.size());
    } else if (const auto resource = chunk.asResource()) {
      if (const auto field = resource->field()) {
        for (const float value : field->data()) sum += value;
      }
    }
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(allocations.count(), 0u);
}

TEST(RoundTrip, PeekTotalSizeFramesAStream) {
  const auto bytes = sampleMessage();
  const auto size = MessageView::peekTotalSize(std::span(bytes).first(16));
  ASSERT_TRUE(size.ok()) << size.error().message;
  EXPECT_EQ(*size, bytes.size());
  EXPECT_FALSE(MessageView::peekTotalSize(std::span(bytes).first(15)).ok());
}

}  // namespace
}  // namespace vrflow::msg
