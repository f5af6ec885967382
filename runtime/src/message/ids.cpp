#include "vrflow/message/ids.hpp"

#include <algorithm>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

namespace vrflow::msg {

std::vector<std::uint32_t> idPrefixes(const std::vector<std::string>& moduleIds) {
  std::vector<std::size_t> order(moduleIds.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return moduleIds[a] < moduleIds[b]; });
  // First pass: every module's own hash, and who keeps it (the smallest id that has it).
  std::vector<std::uint32_t> prefixes(moduleIds.size(), 0);
  std::unordered_map<std::uint32_t, std::size_t> keeper;
  for (const std::size_t m : order) {
    const std::uint32_t hash = fnv1a32(moduleIds[m]);
    if (hash != 0 && keeper.emplace(hash, m).second) prefixes[m] = hash;
  }
  // Second pass, in id order: the others probe upwards past every hash and every taken value.
  std::unordered_set<std::uint32_t> taken;
  for (const auto& [hash, m] : keeper) taken.insert(hash);
  for (const std::size_t m : order) {
    if (prefixes[m] != 0) continue;
    std::uint32_t candidate = fnv1a32(moduleIds[m]);
    do {
      ++candidate;  // wraps past 2^32 - 1 to 0, which is skipped
    } while (candidate == 0 || taken.contains(candidate));
    taken.insert(candidate);
    prefixes[m] = candidate;
  }
  return prefixes;
}

}  // namespace vrflow::msg
