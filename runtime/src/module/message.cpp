#include "vrflow/module/message.hpp"

#include <string>

namespace vrflow {

Result<Message> Message::adopt(ipc::Segment& segment, uint64_t handle) {
  if (!segment.validHandle(handle)) {
    return makeError("handle " + std::to_string(handle) + " is not a block of this segment");
  }
  Message message;
  message.block_ = ipc::BlockRef(&segment, handle);
  auto view = message.block_.view();
  if (!view) return view.error();  // the reference is dropped with `message`
  message.view_ = *view;
  return message;
}

}  // namespace vrflow
