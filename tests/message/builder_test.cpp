#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <vector>

#include "allocation_counter.hpp"
#include "sample_messages.hpp"
#include "vrflow/base/assert.hpp"

namespace vrflow::msg {
namespace {

using testing::AllocationCounter;
using testing::finished;
using testing::sampleMessage;
using testing::sampleStamps;

// Turns a broken precondition into an exception for the duration of a test.
class ThrowOnAssert {
 public:
  ThrowOnAssert() : previous_(setAssertHandler(&handler)) {}
  ~ThrowOnAssert() { setAssertHandler(previous_); }
  ThrowOnAssert(const ThrowOnAssert&) = delete;
  ThrowOnAssert& operator=(const ThrowOnAssert&) = delete;

 private:
  static void handler(const char*, const char* message, const char*, int) {
    throw std::logic_error(message);
  }
  AssertHandler previous_;
};

// A sink that refuses to grow past a fixed capacity (a full shared-memory segment).
class BoundedSink final : public ByteSink {
 public:
  explicit BoundedSink(std::size_t limit) : limit_(limit) {}
  std::byte* grow(std::size_t newCapacity) override {
    if (newCapacity > limit_) return nullptr;
    if (newCapacity > buffer_.size()) buffer_.resize(newCapacity);
    return buffer_.data();
  }
  std::byte* data() override { return buffer_.data(); }
  std::size_t capacity() const override { return buffer_.size(); }

 private:
  std::size_t limit_;
  std::vector<std::byte> buffer_;
};

TEST(MessageBuilder, OnlyChangedParametersTravel) {
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.addObject(1, rigidType()).set("mass", 3.0).set("shape", std::uint64_t{77});
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  const auto object = view->begin()->asObject();
  EXPECT_EQ(object->mask(), (1u << RigidParam::kMass) | (1u << RigidParam::kShape));
  // Header, mask, then two 8-byte entry headers with 8-byte values: nothing else.
  EXPECT_EQ(view->begin()->bytes().size(), kChunkHeaderSize + 8 + (8 + 8) + (8 + 8));
  EXPECT_EQ(bytes.size(), kMessageHeaderSize + view->begin()->bytes().size());
}

TEST(MessageBuilder, ParametersSetOutOfOrderAreStoredByIndex) {
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.addObject(1, rigidType())
      .set(RigidParam::kSdf, std::uint64_t{5})
      .set(RigidParam::kPosition, Vec3{1, 2, 3})
      .set(RigidParam::kMass, 1.0);
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  std::vector<std::uint32_t> order;
  for (const ParamEntry entry : view->begin()->asObject()->params()) order.push_back(entry.index);
  EXPECT_EQ(order, (std::vector<std::uint32_t>{RigidParam::kPosition, RigidParam::kMass,
                                               RigidParam::kSdf}));
}

TEST(MessageBuilder, SettingAParameterTwiceKeepsTheLastValue) {
  VectorSink sink;
  MessageBuilder builder(sink);
  const std::vector<double> longer{1, 2, 3, 4, 5, 6};
  const std::vector<double> shorter{9, 9, 9};
  builder.addObject(1, massSpringType())
      .set(MassSpringParam::kPositions, longer)
      .set(MassSpringParam::kMasses, longer)
      .set(MassSpringParam::kPositions, shorter);
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  const auto object = view->begin()->asObject();
  const auto positions = object->doubleArray(MassSpringParam::kPositions);
  EXPECT_EQ(std::vector<double>(positions->begin(), positions->end()), shorter);
  EXPECT_EQ(object->doubleArray(MassSpringParam::kMasses)->size(), 6u);
}

TEST(MessageBuilder, StampsSetAfterChunksLeaveTheChunksIntact) {
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.addObject(1, pointType()).set(PointParam::kMass, 1.0);
  builder.setStamps(sampleStamps());
  builder.setSource("a-much-longer-source-name-than-before");
  builder.addInt64Stamp("late", 1);
  builder.addObject(2, pointType()).set(PointParam::kMass, 2.0);
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  EXPECT_EQ(view->stamps().source, "a-much-longer-source-name-than-before");
  EXPECT_EQ(view->stamps().user.size(), 4u);
  EXPECT_EQ(view->stamps().user.find("late")->asInt64(), 1);
  ASSERT_EQ(view->chunkCount(), 2u);
  auto it = view->begin();
  EXPECT_EQ(it->asObject()->scalar(PointParam::kMass), 1.0);
  ++it;
  EXPECT_EQ(it->asObject()->scalar(PointParam::kMass), 2.0);
}

TEST(MessageBuilder, ObjectWriterCanStillWriteAfterStampsMoveItsChunk) {
  VectorSink sink;
  MessageBuilder builder(sink);
  ObjectWriter writer = builder.addObject(3, pointType());
  builder.setSource("moved");
  writer.set(PointParam::kVelocity, Vec3{4, 5, 6});
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  EXPECT_EQ(view->begin()->asObject()->vec3(PointParam::kVelocity), (Vec3{4, 5, 6}));
}

TEST(MessageBuilder, UsingAnObjectWriterAfterTheNextChunkIsABug) {
  ThrowOnAssert guard;
  VectorSink sink;
  MessageBuilder builder(sink);
  ObjectWriter first = builder.addObject(1, pointType());
  builder.addDelete(2, pointType());
  EXPECT_THROW(first.set(PointParam::kMass, 1.0), std::logic_error);
}

TEST(MessageBuilder, AValueOfTheWrongKindIsABug) {
  ThrowOnAssert guard;
  VectorSink sink;
  MessageBuilder builder(sink);
  ObjectWriter writer = builder.addObject(1, pointType());
  EXPECT_THROW(writer.set(PointParam::kMass, Vec3{1, 2, 3}), std::logic_error);
  EXPECT_THROW(writer.set(7, 1.0), std::logic_error);
  EXPECT_THROW(writer.set("colour", 1.0), std::logic_error);
  const std::uint32_t badIndices[] = {0, 1, 5};
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  EXPECT_THROW(builder.addMesh(9, false, xyz, badIndices), std::logic_error);
}

TEST(MessageBuilder, ReportsASinkThatCannotGrow) {
  BoundedSink sink(256);
  MessageBuilder builder(sink);
  builder.addObject(1, pointType()).set(PointParam::kMass, 1.0);
  EXPECT_FALSE(builder.failed());
  const std::vector<std::byte> big(1000);
  builder.addRawResource(2, false, big);
  EXPECT_TRUE(builder.failed());
  builder.addObject(3, pointType()).set(PointParam::kMass, 1.0);  // ignored, no crash
  EXPECT_EQ(builder.finish(), 0u);
  EXPECT_TRUE(builder.bytes().empty());

  BoundedSink none(0);
  MessageBuilder starved(none);
  EXPECT_TRUE(starved.failed());
  EXPECT_EQ(starved.finish(), 0u);
}

TEST(MessageBuilder, RawResourceFilledInPlaceReadsBackAsWritten) {
  VectorSink sink(64);
  MessageBuilder builder(sink);
  const std::span<std::byte> body = builder.addRawResourceInPlace(5, true, 13);
  ASSERT_EQ(body.size(), 13u);
  for (std::size_t i = 0; i < body.size(); ++i) body[i] = static_cast<std::byte>(i * 3);
  ASSERT_NE(builder.finish(), 0u);
  const auto view = MessageView::parse(builder.bytes());
  ASSERT_TRUE(view) << view.error().message;
  const auto resource = view->begin()->asResource();
  ASSERT_TRUE(resource);
  EXPECT_EQ(resource->id(), 5u);
  EXPECT_EQ(resource->kind(), ResourceKind::Raw);
  EXPECT_TRUE(resource->dynamic());
  ASSERT_EQ(resource->raw().size(), 13u);
  for (std::size_t i = 0; i < 13; ++i) EXPECT_EQ(resource->raw()[i], static_cast<std::byte>(i * 3));

  BoundedSink small(128);
  MessageBuilder starved(small);
  EXPECT_TRUE(starved.addRawResourceInPlace(1, false, 1000).empty());
  EXPECT_TRUE(starved.failed());
}

TEST(MessageBuilder, ReusedSinkBuildsMessagesWithoutAllocating) {
  VectorSink sink(4096);
  MessageBuilder builder(sink);
  const std::vector<float> xyz(300, 0.5f);
  // The first message initialises the built-in types (once per process) and sizes the sink.
  std::optional<AllocationCounter> allocations;
  for (int i = 0; i < 100; ++i) {
    if (i == 1) allocations.emplace();
    builder.reset();
    builder.setSource("animator");
    builder.setIteration(static_cast<std::uint64_t>(i));
    builder.addObject(1, rigidType()).set(RigidParam::kPosition, Vec3{1, 2, 3});
    builder.addForce(1, ForceEvent{});
    builder.addRawResource(2, true, std::as_bytes(std::span(xyz)));
    ASSERT_GT(builder.finish(), 0u);
  }
  EXPECT_EQ(allocations->count(), 0u);
}

TEST(MessageBuilder, AppendChunksCopiesAnotherMessagesChunksVerbatim) {
  const auto sample = sampleMessage();
  const auto source = MessageView::parse(sample);
  ASSERT_TRUE(source.ok());
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setSource("merge");
  builder.addDelete(99, pointType());
  builder.appendChunks(*source);
  builder.appendChunks(*source);
  const auto merged = finished(builder);
  const auto view = MessageView::parse(merged);
  ASSERT_TRUE(view.ok()) << view.error().message;
  EXPECT_EQ(view->chunkCount(), 1 + 2 * source->chunkCount());
  const auto copied = view->chunkBytes().subspan(view->begin()->bytes().size());
  const auto original = source->chunkBytes();
  EXPECT_TRUE(std::equal(original.begin(), original.end(), copied.begin()));
}

TEST(MessageBuilder, AppendChunkCopiesOneChunkVerbatim) {
  const auto sample = sampleMessage();
  const auto source = MessageView::parse(sample);
  ASSERT_TRUE(source.ok());
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setSource("scatter");
  std::vector<ChunkView> picked;
  for (const ChunkView chunk : *source) {
    if (chunk.index() % 2 == 1) {
      builder.appendChunk(chunk);
      picked.push_back(chunk);
    }
  }
  const auto subset = finished(builder);
  const auto view = MessageView::parse(subset);
  ASSERT_TRUE(view.ok()) << view.error().message;
  ASSERT_EQ(view->chunkCount(), picked.size());
  std::size_t i = 0;
  for (const ChunkView chunk : *view) {
    EXPECT_EQ(chunk.kind(), picked[i].kind());
    EXPECT_EQ(chunk.id(), picked[i].id());
    EXPECT_TRUE(std::equal(chunk.bytes().begin(), chunk.bytes().end(), picked[i].bytes().begin(),
                           picked[i].bytes().end()));
    ++i;
  }
}

TEST(MessageBuilder, StampsOnlyMessagesRefuseChunks) {
  ThrowOnAssert guard;
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setStampsOnly(true);
  EXPECT_THROW(builder.addDelete(1, pointType()), std::logic_error);
  builder.setStampsOnly(false);
  builder.addDelete(1, pointType());
  EXPECT_THROW(builder.setStampsOnly(true), std::logic_error);
}

TEST(MessageBuilder, GrowsFromAnEmptySinkAndKeepsEarlierBytes) {
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setSource("grower");
  std::vector<float> values(5000);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i);
  for (std::uint64_t id = 1; id <= 20; ++id) {
    builder.addObject(id, pointType()).set(PointParam::kMass, static_cast<double>(id));
    builder.addRawResource(1000 + id, true, std::as_bytes(std::span(values)));
  }
  const auto bytes = finished(builder);
  const auto view = MessageView::parse(bytes);
  ASSERT_TRUE(view.ok()) << view.error().message;
  EXPECT_EQ(view->chunkCount(), 40u);
  double sum = 0;
  for (const ChunkView chunk : *view) {
    if (const auto object = chunk.asObject()) sum += *object->scalar(PointParam::kMass);
  }
  EXPECT_EQ(sum, 210.0);
}

}  // namespace
}  // namespace vrflow::msg
