#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>

#include "vrflow/ipc/segment.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::ipc {

/// One counted hold on a message block of a segment: copying adds a reference, destruction
/// drops one. The only handle type of the host's message blocks; the module's Message, the
/// daemon's queues and the network transport all hold blocks through it, and forwarding a
/// message anywhere on the host copies or moves this handle, never the bytes.
class BlockRef {
 public:
  BlockRef() = default;
  /// Takes over one existing reference to `handle` (0: holds nothing).
  BlockRef(Segment* segment, uint64_t handle) : segment_(segment), handle_(handle) {}
  BlockRef(const BlockRef& other) : segment_(other.segment_), handle_(other.handle_) {
    if (handle_ != 0) segment_->retain(handle_);
  }
  BlockRef& operator=(const BlockRef& other) {
    BlockRef copy(other);
    swap(copy);
    return *this;
  }
  BlockRef(BlockRef&& other) noexcept
      : segment_(other.segment_), handle_(std::exchange(other.handle_, 0)) {}
  BlockRef& operator=(BlockRef&& other) noexcept {
    BlockRef moved(std::move(other));
    swap(moved);
    return *this;
  }
  ~BlockRef() {
    if (handle_ != 0) segment_->release(handle_);
  }
  /// Exchanges the blocks two handles hold.
  void swap(BlockRef& other) noexcept {
    std::swap(segment_, other.segment_);
    std::swap(handle_, other.handle_);
  }

  /// True when this holds a block.
  bool valid() const { return handle_ != 0; }
  /// The block's offset in its segment (what travels on the rings).
  uint64_t handle() const { return handle_; }
  /// The segment the block lives in (null when default-constructed).
  Segment* segment() const { return segment_; }
  /// Before pushing the handle on a ring to another process: see Segment::handOver.
  void handOver() const {
    if (handle_ != 0) segment_->handOver(handle_);
  }
  /// Hands the reference over (to a ring): this object no longer holds it.
  uint64_t release() { return std::exchange(handle_, 0); }
  /// The written bytes of the block.
  std::span<const std::byte> bytes() const { return segment_->bytes(handle_); }
  /// How many bytes were written.
  std::size_t size() const { return segment_->block(handle_).used; }
  /// Parses (and fully checks) the message layout of the written bytes.
  Result<msg::MessageView> view() const { return msg::MessageView::parse(bytes()); }

 private:
  Segment* segment_ = nullptr;
  uint64_t handle_ = 0;
};

}  // namespace vrflow::ipc
