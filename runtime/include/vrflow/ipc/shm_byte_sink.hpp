#pragma once
// Internal to vrflow: not part of the module or filter SDK; it may change without notice
// (docs/architecture.md, "The ABI of what outside code links").

#include <cstring>
#include <utility>

#include "vrflow/ipc/segment.hpp"
#include "vrflow/message/builder.hpp"

namespace vrflow::ipc {

/// A message builder's byte sink backed by a shared-memory block; growing moves to a larger
/// block. Modules and daemon filters write their messages through it.
class ShmByteSink final : public msg::ByteSink {
 public:
  ShmByteSink(ipc::Segment& segment, std::size_t initial) : segment_(&segment) { grow(initial); }
  ShmByteSink(const ShmByteSink&) = delete;
  ShmByteSink& operator=(const ShmByteSink&) = delete;
  ~ShmByteSink() override {
    if (handle_ != 0) segment_->release(handle_);
  }

  std::byte* grow(std::size_t newCapacity) override {
    if (handle_ != 0 && newCapacity <= segment_->payloadCapacity(handle_)) return data();
    const uint64_t bigger = segment_->allocate(newCapacity);
    if (bigger == 0) return nullptr;  // exhausted: the builder reports it
    if (handle_ != 0) {
      std::memcpy(segment_->payload(bigger), segment_->payload(handle_),
                  segment_->payloadCapacity(handle_));
      segment_->release(handle_);
    }
    handle_ = bigger;
    return data();
  }
  std::byte* data() override { return handle_ ? segment_->payload(handle_) : nullptr; }
  std::size_t capacity() const override { return handle_ ? segment_->payloadCapacity(handle_) : 0; }

  /// Gives up the block (with its reference) after recording how many bytes were written.
  uint64_t take(std::size_t used) {
    segment_->block(handle_).used = used;
    return std::exchange(handle_, 0);
  }

 private:
  Segment* segment_;
  uint64_t handle_ = 0;
};

}  // namespace vrflow::ipc
