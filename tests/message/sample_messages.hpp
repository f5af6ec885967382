#pragma once

// Messages the message tests (and the fuzz corpus) are built from.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/ids.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::msg::testing {

/// Stamps with every kind of user stamp.
inline Stamps sampleStamps() {
  Stamps stamps;
  stamps.source = "rigid-animator";
  stamps.iteration = 42;
  stamps.simTime = 1.25;
  stamps.timeStep = 0.01;
  stamps.sendTimeNs = 1'700'000'000'123'456'789ull;
  stamps.user = {{"frame", std::int64_t{-7}}, {"gain", 0.5}, {"camera", std::string("left")}};
  return stamps;
}

inline std::vector<std::byte> toBytes(std::string_view text) {
  std::vector<std::byte> bytes(text.size());
  std::memcpy(bytes.data(), text.data(), text.size());
  return bytes;
}

/// Finishes `builder` and copies its message out.
inline std::vector<std::byte> finished(MessageBuilder& builder) {
  const std::size_t size = builder.finish();
  const auto bytes = builder.bytes();
  return std::vector<std::byte>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size));
}

/// A message with every chunk kind: an added rigid body, an updated point, a delete, a raw
/// resource of odd length, a mesh, a scalar and a vector field, a force and a user event.
inline std::vector<std::byte> sampleMessage() {
  VectorSink sink;
  MessageBuilder builder(sink);
  builder.setStamps(sampleStamps());
  builder.addObject(makeId(0x0A000001u, 1), rigidType(), ObjectOp::Add)
      .set(RigidParam::kPosition, Vec3{1.0, 2.0, 3.0})
      .set(RigidParam::kOrientation, Quat{0.0, 0.0, 0.0, 1.0})
      .set(RigidParam::kMass, 2.5)
      .set(RigidParam::kBounds, Aabb{{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}})
      .set(RigidParam::kShape, makeId(0x0A000001u, 3));
  builder.addObject(makeId(0x0A000001u, 2), pointType(), ObjectOp::Update)
      .set(PointParam::kVelocity, Vec3{0.0, -9.81, 0.0});
  builder.addDelete(makeId(0x0A000002u, 9), rigidType());
  builder.addRawResource(makeId(0x0A000001u, 4), false, toBytes("thirteen-byte"));
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  builder.addMesh(makeId(0x0A000001u, 3), false, xyz, indices);
  const float scalars[] = {1, 2, 3, 4, 5, 6, 7, 8};
  builder.addField(makeId(0x0A000001u, 5), true, {2, 2, 2}, 1, Vec3{0, 0, 0}, 0.5, scalars);
  const float vectors[] = {1, 0, 0, 0, 1, 0};
  builder.addField(makeId(0x0A000001u, 6), true, {2, 1, 1}, 3, Vec3{-1, 0, 0}, 0.25, vectors);
  builder.addForce(makeId(0x0A000001u, 1),
                   ForceEvent{{0, 10, 0}, {0, 0, 1}, {0.5, 0.5, 0.5}, 0.02});
  builder.addEvent(makeId(0x0A000003u, 1), 2000, toBytes("select"));
  return finished(builder);
}

/// Offsets of the chunks of a valid message.
inline std::vector<std::size_t> chunkOffsets(const std::vector<std::byte>& bytes) {
  std::vector<std::size_t> offsets;
  const auto view = MessageView::parse(bytes);
  if (!view) return offsets;
  for (const ChunkView chunk : *view) offsets.push_back(static_cast<std::size_t>(chunk.offset()));
  return offsets;
}

/// Overwrites the T at `offset` of `bytes`.
template <typename T>
void poke(std::vector<std::byte>& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

/// Reads the T at `offset` of `bytes`.
template <typename T>
T peek(const std::vector<std::byte>& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof value);
  return value;
}

}  // namespace vrflow::msg::testing
