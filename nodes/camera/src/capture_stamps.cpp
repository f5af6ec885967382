#include "vrflow/camera/capture_stamps.hpp"

namespace vrflow::camera {

std::optional<std::int64_t> int64Stamp(const msg::MessageView& message, std::string_view name) {
  for (const auto stamp : message.stamps().user)
    if (stamp.name() == name) return stamp.asInt64();
  return std::nullopt;
}

void copyCaptureStamps(const msg::MessageView& from, msg::MessageBuilder& to) {
  for (const auto name : {kCaptureStamp, kCaptureIterationStamp})
    if (const auto value = int64Stamp(from, name)) to.addInt64Stamp(name, *value);
}

}  // namespace vrflow::camera
