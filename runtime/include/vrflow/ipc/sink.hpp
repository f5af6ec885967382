#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include "vrflow/ipc/block_ref.hpp"

namespace vrflow::ipc {

/// Where a stream of message blocks goes: a filter's queue or a module's input ring in the
/// daemon, or a connection to another host's daemon in the network transport. Defined here,
/// below both, so that each implements it from public headers only.
class Sink {
 public:
  virtual ~Sink() = default;
  /// False while the destination cannot take a message (backpressure).
  virtual bool hasSpace() const = 0;
  /// Hands one message over (dropped when the destination is gone).
  virtual void push(BlockRef message) = 0;
  /// No message will follow.
  virtual void close() = 0;
  /// True when the destination is a module that has ended (what is pushed is dropped).
  virtual bool ended() const { return false; }
};

}  // namespace vrflow::ipc
