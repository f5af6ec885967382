#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"

// 64-bit object and resource ids: the high 32 bits are the making module's prefix, the low 32
// bits count that module's ids from 1. A module's prefix comes from its id in the application
// (idPrefixes), never from where it runs, so a run's ids do not depend on its placement
// (docs/message-layout.md, "Ids").

namespace vrflow::msg {

/// The id that names no object ("no shape", "no resource").
inline constexpr std::uint64_t kNullId = 0;

/// The most ids one module can make (the counter's range, 1 to 2^32 - 1).
inline constexpr std::uint64_t kIdsPerModule = 0xFFFFFFFFull;

/// FNV-1a, 32 bits, of `text` (used for type ids, source stamps and module id prefixes).
constexpr std::uint32_t fnv1a32(std::string_view text) {
  std::uint32_t hash = 2166136261u;
  for (const char c : text) {
    hash ^= static_cast<std::uint8_t>(c);
    hash *= 16777619u;
  }
  return hash;
}

/// Packs a module's prefix and its counter into one id.
constexpr std::uint64_t makeId(std::uint32_t prefix, std::uint32_t counter) {
  return (std::uint64_t{prefix} << 32) | counter;
}

/// The prefix part of an id: which module made it.
constexpr std::uint32_t prefixOf(std::uint64_t id) {
  return static_cast<std::uint32_t>(id >> 32);
}

/// The counter part of an id.
constexpr std::uint32_t counterOf(std::uint64_t id) {
  return static_cast<std::uint32_t>(id & 0xFFFFFFFFu);
}

/// The id prefix of every module of an application, given all its module ids (after composite
/// expansion, on every host; each id once): entry i is the prefix of `moduleIds[i]`. A module's
/// prefix is FNV-1a 32 of its id; when several ids share a hash (or it is 0), the smallest id
/// keeps it and the others, in id order, take the next values above it that no module's hash
/// names and no module took. So the prefixes depend on the set of ids only: not on their
/// order, nor on hosts or slots; and they are distinct and never 0.
std::vector<std::uint32_t> idPrefixes(const std::vector<std::string>& moduleIds);

/// Hands out one module's ids, prefix << 32 | counter, the counter from 1 up (thread-safe).
class IdSource {
 public:
  /// The ids of the module whose prefix is `prefix`; the first counter is `first` (1 but for
  /// tests of exhaustion).
  explicit IdSource(std::uint32_t prefix = 0, std::uint64_t first = 1)
      : prefix_(prefix), next_(first) {}
  /// The next id; an error when the module has made all kIdsPerModule of its ids.
  Result<std::uint64_t> next() {
    const std::uint64_t counter = next_.fetch_add(1, std::memory_order_relaxed);
    if (counter == 0 || counter > kIdsPerModule) {
      return makeError("ran out of object ids: a module can make " + std::to_string(kIdsPerModule) +
                       " ids in a run (reuse ids of objects that were deleted)");
    }
    return makeId(prefix_, static_cast<std::uint32_t>(counter));
  }
  /// The module's prefix.
  std::uint32_t prefix() const { return prefix_; }

 private:
  std::uint32_t prefix_;
  std::atomic<std::uint64_t> next_;
};

}  // namespace vrflow::msg
