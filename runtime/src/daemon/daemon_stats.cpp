#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "daemon_impl.hpp"
#include "vrflow/message/digest.hpp"

// The daemon's statistics: full-queue warnings, the live snapshots the routing thread publishes
// about twice a second, and the counters of the run report.
namespace vrflow::daemon {

void Daemon::Impl::checkFullQueues(uint64_t now) {
  for (auto& queue : graph->queues) {
    if (!queue.isConnection) continue;
    if (queue.items.size() < queue.capacity) {
      queue.fullSinceNs = 0;
      continue;
    }
    if (queue.fullSinceNs == 0) queue.fullSinceNs = now;
    if (!queue.warnedFull && now - queue.fullSinceNs > options.fullWarningNs) {
      queue.warnedFull = true;
      queue.stayedFull = true;
      const char* policy = queue.policy == app::QueuePolicy::Block        ? "block"
                           : queue.policy == app::QueuePolicy::DropOldest ? "drop-oldest"
                                                                          : "drop-newest";
      // What it means, in the words of the two ends (the ids before the port names).
      const auto owner = [](const std::string& port) {
        return "'" + port.substr(0, port.rfind('.')) + "'";
      };
      const std::string from = owner(queue.from), to = owner(queue.to);
      const std::string effect = queue.policy == app::QueuePolicy::Block
                                     ? ", so " + to + " paces " + from
                                     : "; what does not fit is dropped";
      graph->warnings.push_back("connection " + queue.from + " -> " + queue.to + " stayed full (" +
                                std::to_string(queue.capacity) + " messages, policy " + policy +
                                "): " + to + " takes messages slower than " + from + " sends them" +
                                effect);
    }
  }
}

void Daemon::Impl::publishSnapshot() {
  std::vector<QueueSnapshot> next;
  for (const auto& queue : graph->queues) {
    if (!queue.isConnection) continue;
    next.push_back({queue.from, queue.to, queue.items.size(), queue.capacity, queue.messages,
                    queue.bytes, queue.dropped});
  }
  auto filters = collectFilterStats();
  std::lock_guard lock(warningsMutex);
  snapshot = std::move(next);
  filterSnapshot = std::move(filters);
}

std::vector<FilterStats> Daemon::Impl::collectFilterStats() const {
  std::vector<FilterStats> all;
  for (const auto& node : graph->nodes) {
    FilterStats stats{node->name(), node->type, {}, {}};
    for (std::size_t i = 0; i < node->inputs.size(); ++i) {
      FilterPortStats port;
      port.port = i < node->inputNames.size() ? node->inputNames[i] : node->inputs[i]->from;
      port.messages = node->inputs[i]->messages;
      if (i < node->dropped.size()) {
        for (const auto& [reason, count] : node->dropped[i]) port.dropped[reason] = count;
      }
      stats.inputs.push_back(std::move(port));
    }
    for (std::size_t o = 0; o < node->outputs.size(); ++o) {
      FilterPortStats port;
      port.port = o < node->outputNames.size() ? node->outputNames[o] : "out";
      port.messages = o < node->sent.size() ? node->sent[o] : 0;
      if (o < node->sentNowhere.size() && node->sentNowhere[o] != 0) {
        port.dropped["not connected"] = node->sentNowhere[o];
      }
      stats.outputs.push_back(std::move(port));
    }
    all.push_back(std::move(stats));
  }
  return all;
}

std::vector<FilterStats> Daemon::filterSnapshot() {
  std::lock_guard lock(impl_->warningsMutex);
  return impl_->filterSnapshot;
}

std::vector<FilterStats> Daemon::filterStats() const {
  return impl_->collectFilterStats();
}

std::vector<QueueSnapshot> Daemon::queueSnapshot() {
  std::lock_guard lock(impl_->warningsMutex);
  return impl_->snapshot;
}

void Daemon::Impl::publishWarnings() {
  if (graph->warnings.empty() && graph->merges.empty()) return;
  std::lock_guard lock(warningsMutex);
  for (auto& w : graph->warnings) warnings.push_back(std::move(w));
  graph->warnings.clear();
  traceMerges.insert(traceMerges.end(), graph->merges.begin(), graph->merges.end());
  graph->merges.clear();
}

std::string Daemon::fatalError() {
  std::lock_guard lock(impl_->warningsMutex);
  return impl_->fatal;
}

std::vector<std::string> Daemon::takeWarnings() {
  std::lock_guard lock(impl_->warningsMutex);
  return std::exchange(impl_->warnings, {});
}

std::vector<ipc::TraceMerge> Daemon::takeTraceMerges() {
  std::lock_guard lock(impl_->warningsMutex);
  return std::exchange(impl_->traceMerges, {});
}

std::vector<ConnectionStats> Daemon::connectionStats() const {
  std::vector<ConnectionStats> stats;
  for (const auto& queue : impl_->graph->queues) {
    if (!queue.isConnection) continue;
    stats.push_back(
        {queue.from, queue.to, queue.messages, queue.bytes, queue.dropped, queue.stayedFull});
  }
  return stats;
}

std::vector<OutputStats> Daemon::outputStats() const {
  std::vector<OutputStats> stats;
  for (const auto& [name, filter] : impl_->outputFilters) {
    OutputStats s;
    const auto dot = name.rfind('.');
    s.module = name.substr(0, dot);
    s.port = name.substr(dot + 1);
    s.messages = filter->forwarded();
    if (filter->last().valid()) {
      if (auto view = filter->last().view()) {
        s.hasLast = true;
        s.lastDigest = msg::digest(*view);
        s.lastIteration = view->stamps().iteration;
      }
    }
    stats.push_back(std::move(s));
  }
  return stats;
}

}  // namespace vrflow::daemon
