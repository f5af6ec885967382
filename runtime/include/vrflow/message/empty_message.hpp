#pragma once

#include <cstddef>
#include <vector>

#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/stamps.hpp"

// Messages without chunks: the initial messages that start a cycle, and stamps-only signals.

namespace vrflow::msg {

/// How a chunk-less message is flagged.
enum class EmptyKind {
  Full,       ///< an ordinary message that happens to hold no chunk (a default state)
  StampsOnly  ///< a synchronisation signal (flag bit 0)
};

/// Writes a message with `stamps` and no chunk into `sink`; returns its size, or 0 when the
/// sink could not grow.
std::size_t writeEmptyMessage(ByteSink& sink, const Stamps& stamps, EmptyKind kind);

/// The same message in a new vector.
std::vector<std::byte> makeEmptyMessage(const Stamps& stamps = {},
                                        EmptyKind kind = EmptyKind::Full);

}  // namespace vrflow::msg
