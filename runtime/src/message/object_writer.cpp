#include "vrflow/message/object_writer.hpp"

#include <cstring>
#include <limits>

#include "vrflow/base/assert.hpp"
#include "vrflow/message/builder.hpp"
#include "vrflow/message/packed.hpp"

namespace vrflow::msg {

std::size_t ObjectWriter::indexOf(std::string_view name) const {
  const auto index = type_->indexOf(name);
  VRFLOW_ASSERT(index.has_value(), "the object's type has no parameter of that name");
  return *index;
}

ObjectWriter& ObjectWriter::set(std::size_t index, double value) {
  return write(index, ParamKind::Scalar, &value, sizeof value);
}
ObjectWriter& ObjectWriter::set(std::size_t index, const Vec3& value) {
  return write(index, ParamKind::Vec3, value.data(), sizeof value);
}
ObjectWriter& ObjectWriter::set(std::size_t index, const Quat& value) {
  return write(index, ParamKind::Quat, value.data(), sizeof value);
}
ObjectWriter& ObjectWriter::set(std::size_t index, const Mat3& value) {
  return write(index, ParamKind::Mat3, value.data(), sizeof value);
}
ObjectWriter& ObjectWriter::set(std::size_t index, const Aabb& value) {
  const std::array<double, 6> packed{value.min[0], value.min[1], value.min[2],
                                     value.max[0], value.max[1], value.max[2]};
  return write(index, ParamKind::Aabb, packed.data(), sizeof packed);
}
ObjectWriter& ObjectWriter::set(std::size_t index, std::uint64_t id) {
  return write(index, ParamKind::Id, &id, sizeof id);
}
ObjectWriter& ObjectWriter::set(std::size_t index, std::int64_t value) {
  return write(index, ParamKind::Int64, &value, sizeof value);
}
ObjectWriter& ObjectWriter::set(std::size_t index, std::span<const float> values) {
  return write(index, ParamKind::FloatArray, values.data(), values.size_bytes());
}
ObjectWriter& ObjectWriter::set(std::size_t index, std::span<const double> values) {
  return write(index, ParamKind::DoubleArray, values.data(), values.size_bytes());
}
ObjectWriter& ObjectWriter::set(std::size_t index, std::span<const std::byte> bytes) {
  return write(index, ParamKind::Bytes, bytes.data(), bytes.size());
}

ObjectWriter& ObjectWriter::setEncoded(std::size_t index, std::span<const std::byte> bytes) {
  VRFLOW_ASSERT(index < type_->paramCount(), "parameter index beyond the type's parameter count");
  VRFLOW_ASSERT(validSizeFor(type_->param(index).kind, bytes.size()),
                "encoded parameter size does not suit its kind");
  return write(index, type_->param(index).kind, bytes.data(), bytes.size());
}

ObjectWriter& ObjectWriter::write(std::size_t index, ParamKind kind, const void* data,
                                  std::size_t size) {
  MessageBuilder& b = *builder_;
  if (b.failed_) return *this;
  VRFLOW_ASSERT(b.openObject_ == token_,
                "ObjectWriter used after another chunk was added to its message");
  VRFLOW_ASSERT(index < type_->paramCount(), "parameter index beyond the type's parameter count");
  VRFLOW_ASSERT(type_->param(index).kind == kind, "value type does not match the parameter kind");
  VRFLOW_ASSERT(size <= std::numeric_limits<std::uint32_t>::max(), "parameter over 4 GiB");

  const std::size_t chunk = b.lastChunk_;
  const std::size_t body = chunk + kChunkHeaderSize;
  const std::uint64_t mask = loadRaw<std::uint64_t>(b.base_ + body);
  const std::uint64_t bit = std::uint64_t{1} << index;

  // Entries are sorted by index: find where this one goes (the end, in the usual ascending use).
  std::size_t at = b.size_;
  std::size_t oldLength = 0;
  if ((mask >> index) != 0) {
    at = body + BodyLayout::kObjectMask;
    while (at < b.size_) {
      const std::uint32_t entryIndex = loadRaw<std::uint32_t>(b.base_ + at);
      const std::uint32_t entryLength = loadRaw<std::uint32_t>(b.base_ + at + 4);
      const std::size_t entrySize = BodyLayout::kParamEntryHeader + padTo8(entryLength);
      if (entryIndex == index) oldLength = entrySize;
      if (entryIndex >= index) break;
      at += entrySize;
    }
  }
  const std::size_t newLength = BodyLayout::kParamEntryHeader + padTo8(size);
  VRFLOW_ASSERT(
      b.size_ - oldLength + newLength - chunk <= std::numeric_limits<std::uint32_t>::max(),
      "a chunk is limited to 4 GiB");
  if (!b.splice(at, oldLength, newLength)) return *this;

  std::byte* entry = b.base_ + at;
  storeRaw(entry, static_cast<std::uint32_t>(index));
  storeRaw(entry + 4, static_cast<std::uint32_t>(size));
  if (size != 0) std::memcpy(entry + BodyLayout::kParamEntryHeader, data, size);
  std::memset(entry + BodyLayout::kParamEntryHeader + size, 0, padTo8(size) - size);
  storeRaw(b.base_ + body, mask | bit);
  const std::size_t chunkSize = b.size_ - chunk;
  storeRaw(b.base_ + chunk + ChunkLayout::kSize, static_cast<std::uint32_t>(chunkSize));
  storeRaw(b.base_ + chunk + ChunkLayout::kBodySize,
           static_cast<std::uint32_t>(chunkSize - kChunkHeaderSize));
  return *this;
}

}  // namespace vrflow::msg
