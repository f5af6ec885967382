#include "compose.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "vrflow/ipc/shm_byte_sink.hpp"

namespace vrflow::daemon {

Result<MessageRef> composeMessage(ipc::Segment& segment, std::string_view source,
                                  std::size_t sizeHint,
                                  const std::function<void(msg::MessageBuilder&)>& fill) {
  ipc::ShmByteSink sink(segment, std::max<std::size_t>(sizeHint, 128));
  msg::MessageBuilder builder(sink);
  builder.setSource(source);
  builder.setSendTimeNs(
      static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count()));
  fill(builder);
  const std::size_t used = builder.finish();
  if (used == 0 || sink.data() == nullptr) {
    return makeError("filter '" + std::string(source) + "': shared memory exhausted");
  }
  return MessageRef(&segment, sink.take(used));
}

}  // namespace vrflow::daemon
