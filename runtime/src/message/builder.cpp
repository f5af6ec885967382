#include "vrflow/message/builder.hpp"

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>

#include "vrflow/base/assert.hpp"
#include "vrflow/message/packed.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::msg {
namespace {

constexpr std::size_t kMinCapacity = 256;
constexpr std::size_t kMaxChunkSize = std::numeric_limits<std::uint32_t>::max() & ~std::size_t{7};

}  // namespace

MessageBuilder::MessageBuilder(ByteSink& sink) : sink_(&sink) {
  reset();
}

void MessageBuilder::reset() {
  base_ = sink_->data();
  capacity_ = base_ != nullptr ? sink_->capacity() : 0;
  failed_ = false;
  size_ = 0;
  stampsRaw_ = 0;
  lastChunk_ = 0;
  openObject_ = 0;
  sourceLen_ = 0;
  userStampCount_ = 0;
  chunkCount_ = 0;
  flags_ = 0;
  iteration_ = 0;
  simTime_ = 0.0;
  timeStep_ = 0.0;
  sendTimeNs_ = 0;
  if (ensure(kMessageHeaderSize)) size_ = kMessageHeaderSize;
}

bool MessageBuilder::ensure(std::size_t needed) {
  if (failed_) return false;
  if (needed <= capacity_) return true;
  const std::size_t wanted = std::max({needed, capacity_ * 2, kMinCapacity});
  std::byte* grown = sink_->grow(wanted);
  if (grown == nullptr || sink_->capacity() < needed) {
    failed_ = true;
    base_ = nullptr;
    capacity_ = 0;
    return false;
  }
  base_ = grown;
  capacity_ = sink_->capacity();
  return true;
}

// Replaces [offset, offset + oldLength) with newLength bytes (left unwritten), moving the tail.
bool MessageBuilder::splice(std::size_t offset, std::size_t oldLength, std::size_t newLength) {
  if (newLength > oldLength && !ensure(size_ + (newLength - oldLength))) return false;
  if (failed_) return false;
  const std::size_t tail = offset + oldLength;
  if (tail < size_) std::memmove(base_ + offset + newLength, base_ + tail, size_ - tail);
  size_ = size_ - oldLength + newLength;
  if (lastChunk_ >= tail && lastChunk_ != 0) lastChunk_ = lastChunk_ - oldLength + newLength;
  return true;
}

// Replaces [at, at + oldLength) of the stamps section with newLength bytes and re-pads the
// section to 8 with zeros; returns where the new bytes go.
std::byte* MessageBuilder::replaceInStamps(std::size_t at, std::size_t oldLength,
                                           std::size_t newLength) {
  const std::size_t oldPadding = padTo8(stampsRaw_) - stampsRaw_;
  const std::size_t newRaw = stampsRaw_ - oldLength + newLength;
  VRFLOW_ASSERT(padTo8(newRaw) <= std::numeric_limits<std::uint32_t>::max(),
                "stamps section over 4 GiB");
  const std::size_t newPadding = padTo8(newRaw) - newRaw;
  if (!splice(kMessageHeaderSize + at, oldLength, newLength)) return nullptr;
  if (!splice(kMessageHeaderSize + newRaw, oldPadding, newPadding)) return nullptr;
  std::memset(base_ + kMessageHeaderSize + newRaw, 0, newPadding);
  stampsRaw_ = newRaw;
  return base_ + kMessageHeaderSize + at;
}

void MessageBuilder::setSource(std::string_view source) {
  VRFLOW_ASSERT(source.size() <= std::numeric_limits<std::uint32_t>::max(), "source name too long");
  std::byte* at = replaceInStamps(0, sourceLen_, source.size());
  if (at == nullptr) return;
  if (!source.empty()) std::memcpy(at, source.data(), source.size());
  sourceLen_ = static_cast<std::uint32_t>(source.size());
}

std::byte* MessageBuilder::addUserStamp(std::string_view name, StampType type,
                                        std::size_t valueLength) {
  VRFLOW_ASSERT(!name.empty() && name.size() <= std::numeric_limits<std::uint16_t>::max(),
                "a user stamp name has 1 to 65535 bytes");
  VRFLOW_ASSERT(valueLength <= std::numeric_limits<std::uint32_t>::max(), "user stamp too long");
  VRFLOW_ASSERT(userStampCount_ < std::numeric_limits<std::uint32_t>::max(), "too many stamps");
  const std::size_t entry = kUserStampHeaderSize + name.size() + valueLength;
  std::byte* at = replaceInStamps(stampsRaw_, 0, entry);
  if (at == nullptr) return nullptr;
  storeRaw(at + UserStampLayout::kNameLen, static_cast<std::uint16_t>(name.size()));
  storeRaw(at + UserStampLayout::kType, static_cast<std::uint8_t>(type));
  storeRaw(at + UserStampLayout::kPad, std::uint8_t{0});
  storeRaw(at + UserStampLayout::kValueLen, static_cast<std::uint32_t>(valueLength));
  std::memcpy(at + kUserStampHeaderSize, name.data(), name.size());
  ++userStampCount_;
  return at + kUserStampHeaderSize + name.size();
}

void MessageBuilder::addInt64Stamp(std::string_view name, std::int64_t value) {
  if (std::byte* at = addUserStamp(name, StampType::Int64, sizeof value)) storeRaw(at, value);
}

void MessageBuilder::addDoubleStamp(std::string_view name, double value) {
  if (std::byte* at = addUserStamp(name, StampType::Double, sizeof value)) storeRaw(at, value);
}

void MessageBuilder::addStringStamp(std::string_view name, std::string_view value) {
  std::byte* at = addUserStamp(name, StampType::String, value.size());
  if (at != nullptr && !value.empty()) std::memcpy(at, value.data(), value.size());
}

void MessageBuilder::setStamps(const Stamps& stamps) {
  // Drop the whole variable section, then write the new one.
  if (replaceInStamps(0, stampsRaw_, 0) == nullptr) return;
  sourceLen_ = 0;
  userStampCount_ = 0;
  setSource(stamps.source);
  iteration_ = stamps.iteration;
  simTime_ = stamps.simTime;
  timeStep_ = stamps.timeStep;
  sendTimeNs_ = stamps.sendTimeNs;
  for (const UserStamp& stamp : stamps.user) {
    if (const auto* i = std::get_if<std::int64_t>(&stamp.value)) {
      addInt64Stamp(stamp.name, *i);
    } else if (const auto* d = std::get_if<double>(&stamp.value)) {
      addDoubleStamp(stamp.name, *d);
    } else {
      addStringStamp(stamp.name, std::get<std::string>(stamp.value));
    }
  }
}

void MessageBuilder::setStampsOnly(bool stampsOnly) {
  VRFLOW_ASSERT(!stampsOnly || chunkCount_ == 0, "a stamps-only message holds no chunk");
  flags_ = stampsOnly ? static_cast<std::uint16_t>(flags_ | kFlagStampsOnly)
                      : static_cast<std::uint16_t>(flags_ & ~kFlagStampsOnly);
}

std::byte* MessageBuilder::appendChunk(ChunkKind kind, std::uint8_t op, std::uint16_t subkind,
                                       std::uint64_t id, std::uint32_t typeId,
                                       std::size_t bodySize) {
  VRFLOW_ASSERT((flags_ & kFlagStampsOnly) == 0, "a stamps-only message holds no chunk");
  VRFLOW_ASSERT(bodySize <= kMaxChunkSize - kChunkHeaderSize, "a chunk is limited to 4 GiB");
  VRFLOW_ASSERT(chunkCount_ < std::numeric_limits<std::uint32_t>::max(), "too many chunks");
  openObject_ = 0;
  const std::size_t chunkSize = padTo8(kChunkHeaderSize + bodySize);
  if (!ensure(size_ + chunkSize)) return nullptr;
  std::byte* chunk = base_ + size_;
  storeRaw(chunk + ChunkLayout::kSize, static_cast<std::uint32_t>(chunkSize));
  storeRaw(chunk + ChunkLayout::kKind, static_cast<std::uint8_t>(kind));
  storeRaw(chunk + ChunkLayout::kOp, op);
  storeRaw(chunk + ChunkLayout::kSubkind, subkind);
  storeRaw(chunk + ChunkLayout::kId, id);
  storeRaw(chunk + ChunkLayout::kTypeId, typeId);
  storeRaw(chunk + ChunkLayout::kBodySize, static_cast<std::uint32_t>(bodySize));
  std::memset(chunk + kChunkHeaderSize + bodySize, 0, chunkSize - kChunkHeaderSize - bodySize);
  lastChunk_ = size_;
  size_ += chunkSize;
  ++chunkCount_;
  return chunk + kChunkHeaderSize;
}

ObjectWriter MessageBuilder::addObject(std::uint64_t id, const ObjectType& type, ObjectOp op) {
  VRFLOW_ASSERT(op == ObjectOp::Add || op == ObjectOp::Update, "use addDelete() to delete");
  std::byte* body = appendChunk(ChunkKind::Object, static_cast<std::uint8_t>(op), 0, id, type.id(),
                                BodyLayout::kObjectMask);
  if (body != nullptr) storeRaw(body, std::uint64_t{0});
  openObject_ = ++nextToken_;
  return ObjectWriter(this, &type, openObject_);
}

void MessageBuilder::addDelete(std::uint64_t id, const ObjectType& type) {
  addDelete(id, type.id());
}

void MessageBuilder::addDelete(std::uint64_t id, std::uint32_t typeId) {
  appendChunk(ChunkKind::Object, static_cast<std::uint8_t>(ObjectOp::Delete), 0, id, typeId, 0);
}

void MessageBuilder::addRawResource(std::uint64_t id, bool dynamic,
                                    std::span<const std::byte> bytes) {
  std::byte* body = appendChunk(ChunkKind::Resource, dynamic ? kResourceDynamic : std::uint8_t{0},
                                static_cast<std::uint16_t>(ResourceKind::Raw), id, 0, bytes.size());
  if (body != nullptr && !bytes.empty()) std::memcpy(body, bytes.data(), bytes.size());
}

std::span<std::byte> MessageBuilder::addRawResourceInPlace(std::uint64_t id, bool dynamic,
                                                           std::size_t size) {
  std::byte* body = appendChunk(ChunkKind::Resource, dynamic ? kResourceDynamic : std::uint8_t{0},
                                static_cast<std::uint16_t>(ResourceKind::Raw), id, 0, size);
  if (body == nullptr) return {};
  return {body, size};
}

void MessageBuilder::addMesh(std::uint64_t id, bool dynamic, std::span<const float> xyz,
                             std::span<const std::uint32_t> indices) {
  VRFLOW_ASSERT(xyz.size() % 3 == 0, "a mesh has 3 coordinates per vertex");
  VRFLOW_ASSERT(indices.size() % 3 == 0, "a mesh has 3 indices per triangle");
  VRFLOW_ASSERT(xyz.size() / 3 <= std::numeric_limits<std::uint32_t>::max() &&
                    indices.size() <= std::numeric_limits<std::uint32_t>::max(),
                "mesh too large");
  const auto vertexCount = static_cast<std::uint32_t>(xyz.size() / 3);
  for (const std::uint32_t index : indices) {
    VRFLOW_ASSERT(index < vertexCount, "a mesh index is beyond the vertex count");
  }
  const std::size_t xyzBytes = xyz.size_bytes();
  std::byte* body = appendChunk(ChunkKind::Resource, dynamic ? kResourceDynamic : std::uint8_t{0},
                                static_cast<std::uint16_t>(ResourceKind::Mesh), id, 0,
                                BodyLayout::kMeshHeader + xyzBytes + indices.size_bytes());
  if (body == nullptr) return;
  storeRaw(body, vertexCount);
  storeRaw(body + 4, static_cast<std::uint32_t>(indices.size()));
  if (xyzBytes != 0) std::memcpy(body + BodyLayout::kMeshHeader, xyz.data(), xyzBytes);
  if (!indices.empty()) {
    std::memcpy(body + BodyLayout::kMeshHeader + xyzBytes, indices.data(), indices.size_bytes());
  }
}

void MessageBuilder::addField(std::uint64_t id, bool dynamic,
                              const std::array<std::uint32_t, 3>& dims, std::uint32_t components,
                              const Vec3& origin, double spacing, std::span<const float> data) {
  VRFLOW_ASSERT(components == 1 || components == 3, "a field has 1 or 3 components");
  std::uint64_t count = components;
  bool overflow = false;
  for (const std::uint32_t d : dims) overflow |= __builtin_mul_overflow(count, d, &count);
  VRFLOW_ASSERT(!overflow, "field too large");
  VRFLOW_ASSERT(data.size() == count, "field data size differs from dims * components");
  const auto kind = components == 1 ? ResourceKind::ScalarField : ResourceKind::VectorField;
  std::byte* body = appendChunk(ChunkKind::Resource, dynamic ? kResourceDynamic : std::uint8_t{0},
                                static_cast<std::uint16_t>(kind), id, 0,
                                BodyLayout::kFieldHeader + data.size_bytes());
  if (body == nullptr) return;
  storeRaw(body + 0, dims[0]);
  storeRaw(body + 4, dims[1]);
  storeRaw(body + 8, dims[2]);
  storeRaw(body + 12, components);
  storeRaw(body + 16, origin);
  storeRaw(body + 40, spacing);
  if (!data.empty()) std::memcpy(body + BodyLayout::kFieldHeader, data.data(), data.size_bytes());
}

void MessageBuilder::addForce(std::uint64_t targetId, const ForceEvent& force) {
  std::byte* body = appendChunk(ChunkKind::Event, 0, static_cast<std::uint16_t>(EventKind::Force),
                                targetId, 0, BodyLayout::kForce);
  if (body == nullptr) return;
  storeRaw(body + 0, force.force);
  storeRaw(body + 24, force.torque);
  storeRaw(body + 48, force.point);
  storeRaw(body + 72, force.duration);
}

void MessageBuilder::addEvent(std::uint64_t id, std::uint16_t kind,
                              std::span<const std::byte> payload) {
  VRFLOW_ASSERT(kind >= kFirstUserEventKind, "user event kinds start at 1024; use addForce()");
  std::byte* body = appendChunk(ChunkKind::Event, 0, kind, id, 0, payload.size());
  if (body != nullptr && !payload.empty()) std::memcpy(body, payload.data(), payload.size());
}

void MessageBuilder::appendChunks(const MessageView& other) {
  appendVerbatim(other.chunkBytes(), other.chunkCount());
}

void MessageBuilder::appendChunk(const ChunkView& chunk) {
  appendVerbatim(chunk.bytes(), 1);
}

void MessageBuilder::appendVerbatim(std::span<const std::byte> chunks, std::uint32_t count) {
  VRFLOW_ASSERT((flags_ & kFlagStampsOnly) == 0, "a stamps-only message holds no chunk");
  VRFLOW_ASSERT(std::uint64_t{chunkCount_} + count <= std::numeric_limits<std::uint32_t>::max(),
                "too many chunks");
  if (base_ != nullptr && !chunks.empty()) {
    const auto* begin = reinterpret_cast<const unsigned char*>(chunks.data());
    const auto* ours = reinterpret_cast<const unsigned char*>(base_);
    VRFLOW_ASSERT(std::less<>{}(begin, ours) || !std::less<>{}(begin, ours + capacity_),
                  "appending chunks that live in this builder's own sink");
  }
  openObject_ = 0;
  if (!ensure(size_ + chunks.size())) return;
  if (!chunks.empty()) std::memcpy(base_ + size_, chunks.data(), chunks.size());
  size_ += chunks.size();
  chunkCount_ += count;
}

std::size_t MessageBuilder::finish() {
  if (failed_) return 0;
  std::byte* h = base_;
  storeRaw(h + HeaderLayout::kMagic, kMagic);
  storeRaw(h + HeaderLayout::kVersion, kLayoutVersion);
  storeRaw(h + HeaderLayout::kFlags, flags_);
  storeRaw(h + HeaderLayout::kTotalSize, static_cast<std::uint64_t>(size_));
  storeRaw(h + HeaderLayout::kStampsSize, static_cast<std::uint32_t>(padTo8(stampsRaw_)));
  storeRaw(h + HeaderLayout::kChunkCount, chunkCount_);
  storeRaw(h + HeaderLayout::kIteration, iteration_);
  storeRaw(h + HeaderLayout::kSimTime, simTime_);
  storeRaw(h + HeaderLayout::kTimeStep, timeStep_);
  storeRaw(h + HeaderLayout::kSendTimeNs, sendTimeNs_);
  storeRaw(h + HeaderLayout::kSourceLen, sourceLen_);
  storeRaw(h + HeaderLayout::kUserStampCount, userStampCount_);
  return size_;
}

std::span<const std::byte> MessageBuilder::bytes() const {
  if (failed_ || base_ == nullptr) return {};
  return {base_, size_};
}

}  // namespace vrflow::msg
