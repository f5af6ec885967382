#include <array>

#include "vrflow/message/packed.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::msg {
namespace {

// A valid message with no stamps and no chunk, viewed by default-constructed MessageViews.
std::span<const std::byte> emptyMessage() {
  alignas(8) static const std::array<std::byte, kMessageHeaderSize> bytes = [] {
    std::array<std::byte, kMessageHeaderSize> b{};
    storeRaw(b.data() + HeaderLayout::kMagic, kMagic);
    storeRaw(b.data() + HeaderLayout::kVersion, kLayoutVersion);
    storeRaw(b.data() + HeaderLayout::kTotalSize, std::uint64_t{kMessageHeaderSize});
    return b;
  }();
  return bytes;
}

}  // namespace

MessageView::MessageView() : bytes_(emptyMessage()), types_(&ObjectTypeRegistry::global()) {}

std::uint16_t MessageView::version() const {
  return loadAt<std::uint16_t>(bytes_, HeaderLayout::kVersion);
}

std::uint16_t MessageView::flags() const {
  return loadAt<std::uint16_t>(bytes_, HeaderLayout::kFlags);
}

std::uint32_t MessageView::chunkCount() const {
  return loadAt<std::uint32_t>(bytes_, HeaderLayout::kChunkCount);
}

StampsView MessageView::stamps() const {
  StampsView stamps;
  const std::uint64_t stampsSize = loadAt<std::uint32_t>(bytes_, HeaderLayout::kStampsSize);
  const auto section = sliceAt(bytes_, kMessageHeaderSize, stampsSize);
  const std::uint64_t sourceLen = loadAt<std::uint32_t>(bytes_, HeaderLayout::kSourceLen);
  const auto source = sliceAt(section, 0, sourceLen);
  stamps.source = std::string_view(reinterpret_cast<const char*>(source.data()), source.size());
  stamps.iteration = loadAt<std::uint64_t>(bytes_, HeaderLayout::kIteration);
  stamps.simTime = loadAt<double>(bytes_, HeaderLayout::kSimTime);
  stamps.timeStep = loadAt<double>(bytes_, HeaderLayout::kTimeStep);
  stamps.sendTimeNs = loadAt<std::uint64_t>(bytes_, HeaderLayout::kSendTimeNs);
  const auto packed =
      source.size() == sourceLen ? section.subspan(source.size()) : std::span<const std::byte>{};
  stamps.user = UserStampRange(
      packed, packed.empty() ? 0 : loadAt<std::uint32_t>(bytes_, HeaderLayout::kUserStampCount));
  return stamps;
}

std::span<const std::byte> MessageView::chunkBytes() const {
  const std::uint64_t start =
      kMessageHeaderSize + std::uint64_t{loadAt<std::uint32_t>(bytes_, HeaderLayout::kStampsSize)};
  if (start > bytes_.size()) return {};
  return bytes_.subspan(static_cast<std::size_t>(start));
}

MessageView::Iterator MessageView::begin() const {
  const auto chunks = chunkBytes();
  return Iterator(chunks, bytes_.size() - chunks.size(), 0, chunks.empty() ? 0 : chunkCount(),
                  types_);
}

MessageView::Iterator MessageView::end() const {
  const auto chunks = chunkBytes();
  const std::uint32_t count = chunks.empty() ? 0 : chunkCount();
  return Iterator(std::span<const std::byte>{}, bytes_.size(), count, count, types_);
}

ChunkView MessageView::Iterator::operator*() const {
  const std::uint32_t size = loadAt<std::uint32_t>(rest_, ChunkLayout::kSize);
  return ChunkView(sliceAt(rest_, 0, size), index_, offset_, types_);
}

MessageView::Iterator& MessageView::Iterator::operator++() {
  const std::uint32_t size = loadAt<std::uint32_t>(rest_, ChunkLayout::kSize);
  if (size < kChunkHeaderSize || size > rest_.size()) {
    // Bytes that changed since parse: end the walk rather than read past them.
    rest_ = {};
    index_ = count_;
    return *this;
  }
  rest_ = rest_.subspan(size);
  offset_ += size;
  ++index_;
  return *this;
}

ChunkKind ChunkView::kind() const {
  return static_cast<ChunkKind>(loadAt<std::uint8_t>(bytes_, ChunkLayout::kKind));
}
std::uint8_t ChunkView::op() const {
  return loadAt<std::uint8_t>(bytes_, ChunkLayout::kOp);
}
std::uint16_t ChunkView::subkind() const {
  return loadAt<std::uint16_t>(bytes_, ChunkLayout::kSubkind);
}
std::uint64_t ChunkView::id() const {
  return loadAt<std::uint64_t>(bytes_, ChunkLayout::kId);
}
std::uint32_t ChunkView::typeId() const {
  return loadAt<std::uint32_t>(bytes_, ChunkLayout::kTypeId);
}

std::span<const std::byte> ChunkView::body() const {
  return sliceAt(bytes_, kChunkHeaderSize, loadAt<std::uint32_t>(bytes_, ChunkLayout::kBodySize));
}

std::optional<ObjectView> ChunkView::asObject() const {
  if (kind() != ChunkKind::Object) return std::nullopt;
  return ObjectView(id(), typeId(), static_cast<ObjectOp>(op()), body(), types_->find(typeId()));
}

std::optional<ResourceView> ChunkView::asResource() const {
  if (kind() != ChunkKind::Resource) return std::nullopt;
  return ResourceView(id(), static_cast<ResourceKind>(subkind()), (op() & kResourceDynamic) != 0,
                      body());
}

std::optional<EventView> ChunkView::asEvent() const {
  if (kind() != ChunkKind::Event) return std::nullopt;
  return EventView(id(), subkind(), body());
}

}  // namespace vrflow::msg
