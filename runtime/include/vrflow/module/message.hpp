#pragma once

#include <cstdint>
#include <span>

#include "vrflow/ipc/block_ref.hpp"
#include "vrflow/message/reader.hpp"

namespace vrflow {

/// A message in the host's shared memory, held by reference: copying a Message adds a reference
/// to the same bytes (an ipc::BlockRef), never copies them. Valid until the last holder lets go.
class Message {
 public:
  Message() = default;
  /// Takes over one reference to `handle` and checks its layout; invalid on malformed bytes.
  static Result<Message> adopt(ipc::Segment& segment, uint64_t handle);

  /// True when this holds a message.
  bool valid() const { return block_.valid(); }
  /// The checked, zero-copy view of stamps and chunks.
  const msg::MessageView& view() const { return view_; }
  const msg::MessageView* operator->() const { return &view_; }
  /// The raw bytes (layout of docs/message-layout.md).
  std::span<const std::byte> bytes() const { return block_.bytes(); }
  /// The shared-memory handle (for forwarding without copying).
  uint64_t handle() const { return block_.handle(); }

 private:
  ipc::BlockRef block_;
  msg::MessageView view_;
};

}  // namespace vrflow
