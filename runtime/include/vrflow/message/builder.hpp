#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/layout.hpp"
#include "vrflow/message/object_type.hpp"
#include "vrflow/message/object_writer.hpp"
#include "vrflow/message/stamps.hpp"
#include "vrflow/message/values.hpp"

namespace vrflow::msg {

class ChunkView;
class MessageView;

/// Writes one message (docs/message-layout.md) straight into a ByteSink: set the stamps, add
/// chunks, then finish(). Stamps may be set before or after chunks. Nothing is allocated per
/// chunk; the sink grows geometrically and keeps its capacity across reset().
///
/// Broken preconditions (a parameter of the wrong kind, mesh indices out of range, a chunk over
/// 4 GiB) are bugs and assert. A sink that cannot grow is not a bug: the builder stops writing
/// and finish() returns 0. Floats are not checked here; the reader rejects NaN and infinity.
class MessageBuilder {
 public:
  /// Starts an empty message in `sink`, which must outlive the builder.
  explicit MessageBuilder(ByteSink& sink);
  MessageBuilder(const MessageBuilder&) = delete;
  MessageBuilder& operator=(const MessageBuilder&) = delete;

  /// Starts a new message in the same sink (its capacity is kept).
  void reset();

  /// Replaces every stamp (source, times, user stamps) with `stamps`.
  void setStamps(const Stamps& stamps);
  /// Sets the sending module's id.
  void setSource(std::string_view source);
  /// The sender's iteration number.
  void setIteration(std::uint64_t iteration) { iteration_ = iteration; }
  /// Simulation time of the data, seconds.
  void setSimTime(double simTime) { simTime_ = simTime; }
  /// Simulation time step, seconds.
  void setTimeStep(double timeStep) { timeStep_ = timeStep; }
  /// Wall-clock send time in ns; the only stamp that digests ignore.
  void setSendTimeNs(std::uint64_t sendTimeNs) { sendTimeNs_ = sendTimeNs; }
  /// Appends a user stamp; names are 1..65535 bytes.
  void addInt64Stamp(std::string_view name, std::int64_t value);
  void addDoubleStamp(std::string_view name, double value);
  void addStringStamp(std::string_view name, std::string_view value);
  /// Marks the message stamps-only (a synchronisation signal); it may then hold no chunk.
  void setStampsOnly(bool stampsOnly);

  /// Starts an object chunk (Add or Update); set its changed parameters on the returned writer.
  ObjectWriter addObject(std::uint64_t id, const ObjectType& type, ObjectOp op = ObjectOp::Update);
  /// Adds a chunk deleting object `id` of `type`.
  void addDelete(std::uint64_t id, const ObjectType& type);
  void addDelete(std::uint64_t id, std::uint32_t typeId);
  /// Adds an opaque resource.
  void addRawResource(std::uint64_t id, bool dynamic, std::span<const std::byte> bytes);
  /// Adds an opaque resource of `size` bytes and returns its body to fill in place (zero copy:
  /// the data is written straight into the message, its bytes are not cleared). The span is
  /// valid until the next chunk is added; empty when the sink could not grow.
  std::span<std::byte> addRawResourceInPlace(std::uint64_t id, bool dynamic, std::size_t size);
  /// Adds a triangle mesh: xyz holds 3 floats per vertex, indices 3 per triangle, each index
  /// below the vertex count.
  void addMesh(std::uint64_t id, bool dynamic, std::span<const float> xyz,
               std::span<const std::uint32_t> indices);
  /// Adds a regular grid field of dims[0]*dims[1]*dims[2] cells of `components` floats (1 for a
  /// scalar field, 3 for a vector field), x fastest; `data` must hold exactly that many floats.
  void addField(std::uint64_t id, bool dynamic, const std::array<std::uint32_t, 3>& dims,
                std::uint32_t components, const Vec3& origin, double spacing,
                std::span<const float> data);
  /// Adds a force event for object `targetId`.
  void addForce(std::uint64_t targetId, const ForceEvent& force);
  /// Adds a user event (kind >= kFirstUserEventKind) with an opaque payload.
  void addEvent(std::uint64_t id, std::uint16_t kind, std::span<const std::byte> payload);
  /// Copies every chunk of `other` verbatim (merging); `other` must not live in this sink.
  void appendChunks(const MessageView& other);
  /// Copies one chunk of another message verbatim (to forward a subset of its chunks);
  /// the chunk must not live in this builder's sink.
  void appendChunk(const ChunkView& chunk);

  /// Writes the header and returns the message size, or 0 when the sink could not grow.
  /// The builder may go on (add more, finish again).
  std::size_t finish();

  /// True once the sink failed to grow; everything written since is lost.
  bool failed() const { return failed_; }
  /// Bytes written so far.
  std::size_t size() const { return size_; }
  /// Chunks added so far.
  std::uint32_t chunkCount() const { return chunkCount_; }
  /// The message bytes; complete after finish().
  std::span<const std::byte> bytes() const;

 private:
  friend class ObjectWriter;

  bool ensure(std::size_t needed);
  void appendVerbatim(std::span<const std::byte> chunks, std::uint32_t count);
  bool splice(std::size_t offset, std::size_t oldLength, std::size_t newLength);
  std::byte* replaceInStamps(std::size_t at, std::size_t oldLength, std::size_t newLength);
  std::byte* addUserStamp(std::string_view name, StampType type, std::size_t valueLength);
  std::byte* appendChunk(ChunkKind kind, std::uint8_t op, std::uint16_t subkind, std::uint64_t id,
                         std::uint32_t typeId, std::size_t bodySize);

  ByteSink* sink_;
  std::byte* base_ = nullptr;
  std::size_t capacity_ = 0;
  std::size_t size_ = 0;
  std::size_t stampsRaw_ = 0;     // stamps section bytes before padding
  std::size_t lastChunk_ = 0;     // offset of the last chunk added
  std::uint64_t openObject_ = 0;  // token of the ObjectWriter that may still write, 0 if none
  std::uint64_t nextToken_ = 0;
  std::uint32_t sourceLen_ = 0;
  std::uint32_t userStampCount_ = 0;
  std::uint32_t chunkCount_ = 0;
  std::uint16_t flags_ = 0;
  bool failed_ = false;
  std::uint64_t iteration_ = 0;
  double simTime_ = 0.0;
  double timeStep_ = 0.0;
  std::uint64_t sendTimeNs_ = 0;
};

}  // namespace vrflow::msg
