#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "vrflow/base/result.hpp"
#include "vrflow/message/chunk_views.hpp"
#include "vrflow/message/layout.hpp"
#include "vrflow/message/object_type.hpp"
#include "vrflow/message/stamps.hpp"

namespace vrflow::msg {

/// One chunk of a checked message: its header fields, its body, and typed views.
class ChunkView {
 public:
  ChunkView(std::span<const std::byte> bytes, std::uint32_t index, std::uint64_t offset,
            const ObjectTypeRegistry* types)
      : bytes_(bytes), index_(index), offset_(offset), types_(types) {}

  /// Position among the message's chunks, and byte offset from the message start.
  std::uint32_t index() const { return index_; }
  std::uint64_t offset() const { return offset_; }
  /// Header fields (docs/message-layout.md, "Chunks").
  ChunkKind kind() const;
  std::uint8_t op() const;
  std::uint16_t subkind() const;
  /// The object or resource this chunk concerns (the target object for an event).
  std::uint64_t id() const;
  /// The object type id (object chunks; 0 otherwise).
  std::uint32_t typeId() const;
  /// The body, without the header and padding.
  std::span<const std::byte> body() const;
  /// The whole chunk, header and padding included (to copy it verbatim).
  std::span<const std::byte> bytes() const { return bytes_; }

  /// The typed view matching kind(), or nullopt for another kind.
  std::optional<ObjectView> asObject() const;
  std::optional<ResourceView> asResource() const;
  std::optional<EventView> asEvent() const;

 private:
  std::span<const std::byte> bytes_;
  std::uint32_t index_;
  std::uint64_t offset_;
  const ObjectTypeRegistry* types_;
};

/// A received message, checked once by parse() and then read in place (zero copy). It refers to
/// the bytes it was parsed from, which must stay alive and unchanged. Its accessors never read
/// outside those bytes, even if they were changed after parse (they then return garbage, safely).
class MessageView {
 public:
  /// A view of an empty message (no stamps, no chunk), so a default view is safe to read.
  MessageView();

  /// Checks every byte of `bytes` against docs/message-layout.md: header, stamps, every chunk
  /// header and body. Known object types are checked against `types` (default: the global
  /// registry). On failure the error says what is wrong and at which byte offset.
  static Result<MessageView> parse(std::span<const std::byte> bytes);
  static Result<MessageView> parse(std::span<const std::byte> bytes,
                                   const ObjectTypeRegistry& types);

  /// Reads only the header's magic, version and totalSize (to frame messages in a stream).
  static Result<std::uint64_t> peekTotalSize(std::span<const std::byte> bytes);

  /// The whole message.
  std::span<const std::byte> bytes() const { return bytes_; }
  /// Header fields.
  std::uint16_t version() const;
  std::uint16_t flags() const;
  /// True for a stamps-only message (a synchronisation signal).
  bool stampsOnly() const { return (flags() & kFlagStampsOnly) != 0; }
  /// The stamps; source and user stamps point into the message.
  StampsView stamps() const;
  /// Number of chunks.
  std::uint32_t chunkCount() const;
  /// Every chunk, contiguous and verbatim (MessageBuilder::appendChunks copies it).
  std::span<const std::byte> chunkBytes() const;
  /// The registry the message was checked against.
  const ObjectTypeRegistry& types() const { return *types_; }

  /// Iterates over the chunks in order.
  class Iterator {
   public:
    /// Lets `it->asObject()` work on an iterator that yields chunk views by value.
    struct Arrow {
      ChunkView chunk;
      const ChunkView* operator->() const { return &chunk; }
    };
    using iterator_category = std::forward_iterator_tag;
    using value_type = ChunkView;
    using difference_type = std::ptrdiff_t;
    using pointer = Arrow;
    using reference = ChunkView;
    Iterator() = default;
    Iterator(std::span<const std::byte> rest, std::uint64_t offset, std::uint32_t index,
             std::uint32_t count, const ObjectTypeRegistry* types)
        : rest_(rest), offset_(offset), index_(index), count_(count), types_(types) {}
    ChunkView operator*() const;
    Arrow operator->() const { return Arrow{**this}; }
    Iterator& operator++();
    Iterator operator++(int) {
      Iterator before = *this;
      ++*this;
      return before;
    }
    bool operator==(const Iterator& other) const { return index_ == other.index_; }

   private:
    std::span<const std::byte> rest_;
    std::uint64_t offset_ = 0;
    std::uint32_t index_ = 0;
    std::uint32_t count_ = 0;
    const ObjectTypeRegistry* types_ = nullptr;
  };
  /// The chunks, in order.
  Iterator begin() const;
  Iterator end() const;

 private:
  MessageView(std::span<const std::byte> bytes, const ObjectTypeRegistry* types)
      : bytes_(bytes), types_(types) {}
  std::span<const std::byte> bytes_;
  const ObjectTypeRegistry* types_;
};

}  // namespace vrflow::msg
