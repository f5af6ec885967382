#pragma once

#include <cstdint>
#include <span>
#include <utility>

#include "vrflow/ipc/segment.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow::daemon {

/// The daemon's hold on a message block: copying adds a reference, destruction drops one.
/// Forwarding a message anywhere on the host moves or copies this handle, never the bytes.
class MessageRef {
 public:
  MessageRef() = default;
  /// Takes over one existing reference.
  MessageRef(ipc::Segment* segment, uint64_t handle) : segment_(segment), handle_(handle) {}
  MessageRef(const MessageRef& other) : segment_(other.segment_), handle_(other.handle_) {
    if (handle_ != 0) segment_->retain(handle_);
  }
  MessageRef& operator=(const MessageRef& other) {
    MessageRef copy(other);
    swap(copy);
    return *this;
  }
  MessageRef(MessageRef&& other) noexcept
      : segment_(other.segment_), handle_(std::exchange(other.handle_, 0)) {}
  MessageRef& operator=(MessageRef&& other) noexcept {
    MessageRef moved(std::move(other));
    swap(moved);
    return *this;
  }
  ~MessageRef() {
    if (handle_ != 0) segment_->release(handle_);
  }
  void swap(MessageRef& other) noexcept {
    std::swap(segment_, other.segment_);
    std::swap(handle_, other.handle_);
  }

  bool valid() const { return handle_ != 0; }
  uint64_t handle() const { return handle_; }
  /// Before pushing the handle on a ring to another process: see ipc::Segment::handOver.
  void handOver() const {
    if (handle_ != 0) segment_->handOver(handle_);
  }
  /// Hands the reference over (to a ring): this object no longer holds it.
  uint64_t release() { return std::exchange(handle_, 0); }
  std::span<const std::byte> bytes() const { return segment_->bytes(handle_); }
  std::size_t size() const { return segment_->block(handle_).used; }
  /// Parses (and fully checks) the layout.
  Result<msg::MessageView> view() const { return msg::MessageView::parse(bytes()); }

 private:
  ipc::Segment* segment_ = nullptr;
  uint64_t handle_ = 0;
};

}  // namespace vrflow::daemon
