#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "sample_messages.hpp"

namespace vrflow::msg {
namespace {

using testing::AllocationCounter;
using testing::chunkOffsets;
using testing::finished;
using testing::peek;
using testing::poke;
using testing::sampleMessage;

// Chunk order in sampleMessage().
enum SampleChunk : std::size_t {
  kRigid,
  kPoint,
  kDelete,
  kRaw,
  kMesh,
  kScalars,
  kVectors,
  kForce,
  kUser
};

// Parses `bytes`, expects a rejection and returns its message.
std::string rejection(const std::vector<std::byte>& bytes) {
  const auto view = MessageView::parse(bytes);
  if (view.ok()) return "<accepted>";
  return view.error().message;
}

// Success when `message` contains `part`; otherwise shows the message.
::testing::AssertionResult mentions(const std::string& message, const std::string& part) {
  if (message.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "error \"" << message << "\" does not mention \"" << part << "\"";
}

class Rejects : public ::testing::Test {
 protected:
  std::vector<std::byte> message = sampleMessage();
  std::vector<std::size_t> chunks = chunkOffsets(message);
  std::size_t body(SampleChunk chunk) const { return chunks[chunk] + kChunkHeaderSize; }
};

TEST_F(Rejects, TheSampleItselfIsValid) {
  ASSERT_EQ(chunks.size(), 9u);
  EXPECT_EQ(rejection(message), "<accepted>");
}

TEST_F(Rejects, EveryTruncation) {
  for (std::size_t length = 0; length < message.size(); ++length) {
    const std::vector<std::byte> prefix(message.begin(),
                                        message.begin() + static_cast<std::ptrdiff_t>(length));
    EXPECT_NE(rejection(prefix), "<accepted>") << "prefix of " << length << " bytes";
  }
}

TEST_F(Rejects, EveryTruncationEvenWhenTotalSizeIsForgedToMatch) {
  for (std::size_t length = kMessageHeaderSize; length < message.size(); ++length) {
    std::vector<std::byte> prefix(message.begin(),
                                  message.begin() + static_cast<std::ptrdiff_t>(length));
    poke<std::uint64_t>(prefix, HeaderLayout::kTotalSize, length);
    EXPECT_NE(rejection(prefix), "<accepted>") << "prefix of " << length << " bytes";
  }
}

TEST_F(Rejects, BadMagic) {
  poke<std::uint32_t>(message, HeaderLayout::kMagic, 0x12345678u);
  EXPECT_TRUE(mentions(rejection(message), "magic 0x12345678 is not 'VRFM'"));
}

TEST_F(Rejects, AnotherLayoutVersion) {
  poke<std::uint16_t>(message, HeaderLayout::kVersion, 2);
  EXPECT_TRUE(mentions(rejection(message), "layout version 2 is not supported"));
}

TEST_F(Rejects, UnknownFlags) {
  poke<std::uint16_t>(message, HeaderLayout::kFlags, 0x8000);
  EXPECT_TRUE(mentions(rejection(message), "unknown flags 0x8000"));
}

TEST_F(Rejects, StampsOnlyMessageWithChunks) {
  poke<std::uint16_t>(message, HeaderLayout::kFlags, kFlagStampsOnly);
  EXPECT_TRUE(mentions(rejection(message), "stamps-only message declares 9 chunks"));
}

TEST_F(Rejects, TrailingBytesAfterTheLastChunk) {
  poke<std::uint32_t>(message, HeaderLayout::kChunkCount, 8);
  EXPECT_TRUE(mentions(rejection(message), "bytes follow the last of the 8 chunks"));
}

TEST_F(Rejects, ChunkSizePastTheEnd) {
  poke<std::uint32_t>(message, chunks[kRaw] + ChunkLayout::kSize, 4096);
  EXPECT_EQ(rejection(message), "chunk 3 at offset " + std::to_string(chunks[kRaw]) +
                                    ": size 4096 runs past the end of the message (" +
                                    std::to_string(message.size()) + " bytes)");
}

TEST_F(Rejects, ChunkSizeNotAMultipleOf8) {
  poke<std::uint32_t>(message, chunks[kRaw] + ChunkLayout::kSize,
                      peek<std::uint32_t>(message, chunks[kRaw]) - 4);
  EXPECT_TRUE(mentions(rejection(message), "is not a multiple of 8"));
}

TEST_F(Rejects, ChunkSizeSmallerThanItsHeader) {
  for (const std::uint32_t size : {0u, 8u, 16u}) {
    poke<std::uint32_t>(message, chunks[kDelete] + ChunkLayout::kSize, size);
    EXPECT_TRUE(mentions(rejection(message), "chunk 2 at offset")) << size;
    EXPECT_TRUE(mentions(rejection(message), "is smaller than the 24-byte chunk header")) << size;
  }
}

TEST_F(Rejects, BodySizeThatDoesNotFillTheChunk) {
  poke<std::uint32_t>(message, chunks[kRaw] + ChunkLayout::kBodySize, 40);
  EXPECT_TRUE(mentions(rejection(message), "bodySize 40 does not fill"));
}

TEST_F(Rejects, NonZeroPadding) {
  // The raw resource has 13 bytes: 3 bytes of padding follow.
  message[body(kRaw) + 13] = std::byte{1};
  EXPECT_TRUE(mentions(rejection(message), "padding at offset"));
}

TEST_F(Rejects, UnknownChunkKindResourceKindAndEventKind) {
  auto kind = message;
  poke<std::uint8_t>(kind, chunks[kRaw] + ChunkLayout::kKind, 9);
  EXPECT_TRUE(mentions(rejection(kind), "unknown chunk kind 9"));
  auto resource = message;
  poke<std::uint16_t>(resource, chunks[kRaw] + ChunkLayout::kSubkind, 77);
  EXPECT_TRUE(mentions(rejection(resource), "unknown resource kind 77"));
  auto event = message;
  poke<std::uint16_t>(event, chunks[kUser] + ChunkLayout::kSubkind, 5);
  EXPECT_TRUE(mentions(rejection(event), "unknown event kind 5"));
}

TEST_F(Rejects, MeshIndexOutOfRange) {
  const std::size_t indices = body(kMesh) + BodyLayout::kMeshHeader + 48;  // 4 vertices
  poke<std::uint32_t>(message, indices + 20, 4);                           // index 5
  EXPECT_TRUE(mentions(rejection(message), "mesh index 5"));
  EXPECT_TRUE(mentions(rejection(message), "is 4, not below the vertex count 4"));
}

TEST_F(Rejects, MeshCountsThatDisagreeWithTheBody) {
  auto notTriangles = message;
  poke<std::uint32_t>(notTriangles, body(kMesh) + 4, 5);
  EXPECT_TRUE(mentions(rejection(notTriangles), "not a multiple of 3"));
  auto tooManyVertices = message;
  poke<std::uint32_t>(tooManyVertices, body(kMesh), 0xFFFFFFFFu);
  EXPECT_TRUE(mentions(rejection(tooManyVertices), "4294967295 vertices"));
}

TEST_F(Rejects, FieldDimsOverflowing64Bits) {
  for (const std::size_t at : {0u, 4u, 8u})
    poke<std::uint32_t>(message, body(kScalars) + at, 0xFFFFFFFFu);
  EXPECT_TRUE(mentions(rejection(message), "overflows 64 bits"));
}

TEST_F(Rejects, FieldDimsThatDisagreeWithTheBody) {
  auto dims = message;
  poke<std::uint32_t>(dims, body(kScalars), 3);
  EXPECT_TRUE(mentions(rejection(dims), "a field of 3 x 2 x 2 x 1 floats takes"));
  auto components = message;
  poke<std::uint32_t>(components, body(kVectors) + 12, 1);
  EXPECT_TRUE(mentions(rejection(components), "a vector field has 3 components, not 1"));
  auto spacing = message;
  poke<double>(spacing, body(kScalars) + 40, 0.0);
  EXPECT_TRUE(mentions(rejection(spacing), "spacing"));
}

TEST_F(Rejects, NaNAndInfinityWhereverFloatsTravel) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto simTime = message;
  poke<double>(simTime, HeaderLayout::kSimTime, nan);
  EXPECT_TRUE(mentions(rejection(simTime), "simTime"));
  auto force = message;
  poke<double>(force, body(kForce) + 8, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(mentions(rejection(force), "force event holds a NaN"));
  auto vertex = message;
  poke<float>(vertex, body(kMesh) + BodyLayout::kMeshHeader + 28,  // vertex 2, y
              std::numeric_limits<float>::quiet_NaN());
  EXPECT_TRUE(mentions(rejection(vertex), "mesh vertex 2"));
  auto field = message;
  poke<float>(field, body(kScalars) + BodyLayout::kFieldHeader + 24,  // value 6
              std::numeric_limits<float>::infinity());
  EXPECT_TRUE(mentions(rejection(field), "field value 6"));
  auto mass = message;
  // The rigid body's entries: mask, position (8+24), orientation (8+32), mass (8+8).
  poke<double>(mass, body(kRigid) + 8 + 32 + 40 + 8, nan);
  EXPECT_TRUE(mentions(rejection(mass), "parameter 'mass' (4) of type 'rigid'"));
}

// Builds an object chunk of a type that looks like a built-in one but is not.
std::vector<std::byte> impostor(const char* name, std::vector<ParamDecl> params, std::size_t index,
                                std::span<const std::byte> value) {
  auto type = ObjectType::create(name, std::move(params));
  EXPECT_TRUE(type.ok());
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.addObject(1, *type).setEncoded(index, value);
  return finished(builder);
}

TEST(RejectsObject, ParameterOfTheWrongSizeForAKnownType) {
  const std::byte five[5]{};
  const auto bytes = impostor("rigid", {{"position", ParamKind::Bytes}}, 0, five);
  EXPECT_TRUE(mentions(rejection(bytes),
                       "parameter 'position' (0) of type 'rigid' has 5 bytes; a Vec3 has 24"));
  const std::byte twelve[12]{};
  const auto array =
      impostor("massspring", {{"positions", ParamKind::Bytes}}, 0, std::span(twelve).first(10));
  EXPECT_TRUE(mentions(rejection(array), "has 10 bytes, not a multiple of 8"));
}

TEST(RejectsObject, ParameterIndexBeyondTheTypesParameterCount) {
  const std::byte eight[8]{};
  const auto bytes = impostor("point",
                              {{"a", ParamKind::Scalar},
                               {"b", ParamKind::Scalar},
                               {"c", ParamKind::Scalar},
                               {"d", ParamKind::Scalar},
                               {"e", ParamKind::Scalar}},
                              4, eight);
  EXPECT_TRUE(mentions(rejection(bytes), "names parameter 4 but type 'point' has 3 parameters"));
}

TEST(RejectsObject, UnknownTypesStayReadableButAreCheckedStructurally) {
  const std::byte five[5]{std::byte{1}, std::byte{2}, std::byte{3}, std::byte{4}, std::byte{5}};
  const auto bytes = impostor("gizmo", {{"blob", ParamKind::Bytes}}, 0, five);
  EXPECT_EQ(rejection(bytes), "<accepted>");
}

TEST_F(Rejects, MaskAndEntriesThatDisagree) {
  const std::size_t mask = body(kRigid);
  const auto original = peek<std::uint64_t>(message, mask);
  auto extraBit = message;
  poke<std::uint64_t>(extraBit, mask, original | (1u << RigidParam::kInertia));
  EXPECT_TRUE(mentions(rejection(extraBit), "is for parameter 6 but the mask"));
  auto missingEntry = message;
  poke<std::uint64_t>(missingEntry, mask, original | (1ull << RigidParam::kSdf));
  EXPECT_TRUE(mentions(rejection(missingEntry), "names parameter 8 but the chunk has no entry"));
  auto missingBit = message;
  poke<std::uint64_t>(missingBit, mask, original & ~(1ull << RigidParam::kShape));
  EXPECT_TRUE(mentions(rejection(missingBit), "which the mask"));
  auto reordered = message;
  poke<std::uint32_t>(reordered, mask + 8, RigidParam::kOrientation);  // first entry's index
  EXPECT_TRUE(mentions(rejection(reordered), "is for parameter 1 but the mask"));
}

TEST_F(Rejects, DeleteWithABody) {
  poke<std::uint8_t>(message, chunks[kRigid] + ChunkLayout::kOp,
                     static_cast<std::uint8_t>(ObjectOp::Delete));
  EXPECT_TRUE(mentions(rejection(message), "a delete has an empty body"));
}

TEST_F(Rejects, ForgedStampsSections) {
  auto stampsSize = message;
  poke<std::uint32_t>(stampsSize, HeaderLayout::kStampsSize, 0xFFFFFFF8u);
  EXPECT_TRUE(mentions(rejection(stampsSize), "stamps section of 4294967288 bytes runs past"));
  auto sourceLen = message;
  poke<std::uint32_t>(sourceLen, HeaderLayout::kSourceLen, 0xFFFFFFFFu);
  EXPECT_TRUE(mentions(rejection(sourceLen), "source name of 4294967295 bytes"));
  auto count = message;
  poke<std::uint32_t>(count, HeaderLayout::kUserStampCount, 0xFFFFFFFFu);
  EXPECT_TRUE(mentions(rejection(count), "user stamp 3 at offset"));
  auto valueLen = message;
  const std::size_t firstStamp = kMessageHeaderSize + testing::sampleStamps().source.size();
  poke<std::uint32_t>(valueLen, firstStamp + UserStampLayout::kValueLen, 0xFFFFFFFFu);
  EXPECT_TRUE(mentions(rejection(valueLen), "run past the stamps section"));
  auto type = message;
  poke<std::uint8_t>(type, firstStamp + UserStampLayout::kType, 9);
  EXPECT_TRUE(mentions(rejection(type), "unknown stamp type 9"));
}

// Every size field forged to its largest values: parse must reject without crashing and without
// any allocation sized from the field.
TEST_F(Rejects, ForgedHugeSizeFieldsNeverAllocateOrCrash) {
  struct Field {
    std::size_t offset;
    std::size_t width;
  };
  std::vector<Field> fields = {
      {HeaderLayout::kTotalSize, 8},      {HeaderLayout::kStampsSize, 4},
      {HeaderLayout::kChunkCount, 4},     {HeaderLayout::kSourceLen, 4},
      {HeaderLayout::kUserStampCount, 4},
  };
  for (const std::size_t chunk : chunks) {
    fields.push_back({chunk + ChunkLayout::kSize, 4});
    fields.push_back({chunk + ChunkLayout::kBodySize, 4});
  }
  fields.push_back({body(kRigid), 8});       // mask
  fields.push_back({body(kRigid) + 8, 4});   // first entry's index
  fields.push_back({body(kRigid) + 12, 4});  // first entry's length
  fields.push_back({body(kMesh), 4});
  fields.push_back({body(kMesh) + 4, 4});
  for (const std::size_t at : {0u, 4u, 8u, 12u}) fields.push_back({body(kScalars) + at, 4});

  AllocationCounter allocations;
  for (const Field& field : fields) {
    for (const std::uint64_t value :
         {std::uint64_t{0xFFFFFFFFFFFFFFFFull}, std::uint64_t{0xFFFFFFF8u},
          std::uint64_t{0x80000000u}, std::uint64_t{0x7FFFFFFFu}, std::uint64_t{1}}) {
      auto forged = message;
      std::memcpy(forged.data() + field.offset, &value, field.width);
      if (forged == message) continue;
      EXPECT_NE(rejection(forged), "<accepted>") << "field at offset " << field.offset;
    }
  }
  EXPECT_LT(allocations.largest(), std::size_t{1} << 16);
}

// Reads everything a view offers; returns a number so the reads are not optimised away.
double readEverything(const MessageView& view) {
  double sum = static_cast<double>(view.stamps().source.size());
  for (const UserStampView stamp : view.stamps().user) sum += stamp.asDouble().value_or(0.0);
  for (const ChunkView chunk : view) {
    if (const auto object = chunk.asObject()) {
      for (const ParamEntry entry : object->params())
        sum += static_cast<double>(entry.bytes.size());
      sum += object->scalar(0).value_or(0.0);
    } else if (const auto resource = chunk.asResource()) {
      if (const auto mesh = resource->mesh()) {
        for (const std::uint32_t index : mesh->indices()) sum += mesh->vertex(index)[0];
      }
      if (const auto field = resource->field()) {
        for (const float value : field->data()) sum += value;
      }
    } else if (const auto event = chunk.asEvent()) {
      if (const auto force = event->force()) sum += force->duration;
    }
  }
  return sum;
}

// A deterministic stand-in for the fuzz target in every test run (ASan builds included).
TEST_F(Rejects, EverySingleByteCorruptionIsRejectedOrReadSafely) {
  std::size_t accepted = 0;
  for (std::size_t at = 0; at < message.size(); ++at) {
    for (const int flip : {0x01, 0x80, 0xFF}) {
      auto corrupt = message;
      corrupt[at] ^= static_cast<std::byte>(flip);
      const auto view = MessageView::parse(corrupt);
      if (!view.ok()) continue;
      ++accepted;
      EXPECT_TRUE(std::isfinite(readEverything(*view))) << "byte " << at;
    }
  }
  EXPECT_GT(accepted, 0u);  // ids, names and values change without breaking the layout
}

}  // namespace
}  // namespace vrflow::msg
