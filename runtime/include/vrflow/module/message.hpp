#pragma once

#include <cstdint>
#include <span>

#include "vrflow/ipc/segment.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow {

/// A message in the host's shared memory, held by reference: copying a Message adds a reference
/// to the same bytes, never copies them. Valid until the last holder lets go.
class Message {
 public:
  Message() = default;
  /// Takes over one reference to `handle` and checks its layout; invalid on malformed bytes.
  static Result<Message> adopt(ipc::Segment& segment, uint64_t handle);

  Message(const Message& other);
  Message& operator=(const Message& other);
  Message(Message&& other) noexcept;
  Message& operator=(Message&& other) noexcept;
  ~Message();

  /// True when this holds a message.
  bool valid() const { return handle_ != 0; }
  /// The checked, zero-copy view of stamps and chunks.
  const msg::MessageView& view() const { return view_; }
  const msg::MessageView* operator->() const { return &view_; }
  /// The raw bytes (layout of docs/message-layout.md).
  std::span<const std::byte> bytes() const { return segment_->bytes(handle_); }
  /// The shared-memory handle (for forwarding without copying).
  uint64_t handle() const { return handle_; }

 private:
  ipc::Segment* segment_ = nullptr;
  uint64_t handle_ = 0;
  msg::MessageView view_;
};

}  // namespace vrflow
