#pragma once

#include <cstddef>
#include <functional>
#include <string_view>

#include "vrflow/daemon/message_ref.hpp"
#include "vrflow/message/builder.hpp"

namespace vrflow::daemon {

/// A new message written by `fill` straight into `segment`, from `source`, sent now (what
/// FilterContext::compose does for the daemon's filters and for the filter test harness).
/// Fails when the segment is exhausted.
Result<MessageRef> composeMessage(ipc::Segment& segment, std::string_view source,
                                  std::size_t sizeHint,
                                  const std::function<void(msg::MessageBuilder&)>& fill);

}  // namespace vrflow::daemon
