#pragma once

#include <cstdint>

#include "vrflow/message/reader.hpp"

namespace vrflow::msg {

/// XXH3-64 (seed 0) of a message's bytes with the sendTimeNs field read as zero: it covers the
/// source, iteration, simulation time and step, user stamps, flags and every chunk byte, and
/// not the wall-clock send time. Same content, same digest, on any host and at any send time.
std::uint64_t digest(const MessageView& message);

}  // namespace vrflow::msg
