#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vrflow::app {

/// The candidate closest to `word` when it is a plausible typo of it (edit distance at most 2
/// and less than half the word), or nullopt: the "did you mean" of the validator's messages
/// and of `vrflow types`.
std::optional<std::string> closestName(std::string_view word,
                                       const std::vector<std::string>& candidates);

}  // namespace vrflow::app
