#include "vrflow/module/message.hpp"

#include <string>
#include <utility>

namespace vrflow {

Result<Message> Message::adopt(ipc::Segment& segment, uint64_t handle) {
  if (!segment.validHandle(handle)) {
    return makeError("handle " + std::to_string(handle) + " is not a block of this segment");
  }
  Message message;
  message.segment_ = &segment;
  message.handle_ = handle;
  auto view = msg::MessageView::parse(segment.bytes(handle));
  if (!view) return view.error();  // the reference is dropped by ~Message
  message.view_ = *view;
  return message;
}

Message::Message(const Message& other)
    : segment_(other.segment_), handle_(other.handle_), view_(other.view_) {
  if (handle_ != 0) segment_->retain(handle_);
}

Message& Message::operator=(const Message& other) {
  if (this != &other) {
    Message copy(other);
    *this = std::move(copy);
  }
  return *this;
}

Message::Message(Message&& other) noexcept
    : segment_(other.segment_), handle_(std::exchange(other.handle_, 0)), view_(other.view_) {}

Message& Message::operator=(Message&& other) noexcept {
  if (this != &other) {
    if (handle_ != 0) segment_->release(handle_);
    segment_ = other.segment_;
    handle_ = std::exchange(other.handle_, 0);
    view_ = other.view_;
  }
  return *this;
}

Message::~Message() {
  if (handle_ != 0) segment_->release(handle_);
}

}  // namespace vrflow
