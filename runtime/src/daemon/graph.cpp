#include "graph.hpp"

#include <algorithm>
#include <chrono>

#include "compose.hpp"
#include "vrflow/message/ids.hpp"

namespace vrflow::daemon {
void QueueSink::push(MessageRef message) {
  Queue& q = *queue_;
  const std::size_t size = message.size();
  if (q.items.size() >= q.capacity) {
    if (q.policy == app::QueuePolicy::DropNewest) {
      ++q.dropped;
      return;
    }
    if (q.policy == app::QueuePolicy::DropOldest) {
      q.items.pop_front();
      ++q.dropped;
    }
  }
  q.items.push_back(std::move(message));
  ++q.messages;
  q.bytes += size;
}

void RingSink::push(MessageRef message) {
  if (ended()) return;  // dropped: nobody will ever read it
  message.handOver();
  const bool pushed = ring_.push(message.handle());
  if (pushed) {
    message.release();  // the ring holds the reference now
    slot_.wake();
  }
}

void Node::countDropped(std::size_t i, uint64_t count, std::string_view reason) {
  if (count == 0) return;
  if (dropped.size() < inputs.size()) dropped.resize(inputs.size());
  auto& byReason = dropped[i];
  const auto found = byReason.find(reason);
  if (found != byReason.end()) {
    found->second += count;
  } else {
    byReason.emplace(std::string(reason), count);
  }
}

bool Node::outputEnded(std::size_t o) const {
  const auto& sinks = outputs[o];
  return !sinks.empty() &&
         std::all_of(sinks.begin(), sinks.end(), [](const auto& sink) { return sink->ended(); });
}

bool Node::runCountsIterations() const {
  return graph_->countsIterations;
}

bool Node::canEmit(std::size_t o) const {
  return std::all_of(outputs[o].begin(), outputs[o].end(),
                     [](const auto& sink) { return sink->hasSpace(); });
}

void Node::emit(std::size_t o, MessageRef message) {
  ++emitted;
  ++graph_->operations;
  if (sent.size() < outputs.size()) {
    sent.resize(outputs.size());
    sentNowhere.resize(outputs.size());
  }
  ++sent[o];
  auto& sinks = outputs[o];
  if (sinks.empty()) {  // nothing connected: dropped here, as in FlowVR
    ++sentNowhere[o];
    return;
  }
  for (std::size_t i = 0; i + 1 < sinks.size(); ++i) sinks[i]->push(message);
  sinks.back()->push(std::move(message));
}

void Node::recordMerge(std::span<const msg::MessageView> views) {
  if (!graph_->traceMerges || views.size() < 2) return;
  // The merged message is stamped with the first part's source and the largest iteration.
  uint64_t mergedIteration = 0;
  for (const auto& view : views)
    mergedIteration = std::max(mergedIteration, view.stamps().iteration);
  const uint32_t mergedHash = msg::fnv1a32(views.front().stamps().source);
  for (const auto& view : views) {
    const auto stamps = view.stamps();
    graph_->merges.push_back(
        {mergedHash, msg::fnv1a32(stamps.source), mergedIteration, stamps.iteration});
  }
}

Result<MessageRef> Node::compose(std::size_t sizeHint,
                                 const std::function<void(msg::MessageBuilder&)>& fill) {
  return composeMessage(*graph_->segment, id_, sizeHint, fill);
}

uint64_t Node::nowNs() const {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count());
}

void Node::wakeAfter(uint64_t delayNs) {
  const uint64_t at = nowNs() + delayNs;
  if (graph_->wakeAtNs == 0 || at < graph_->wakeAtNs) graph_->wakeAtNs = at;
}

void Node::warn(const std::string& message) {
  graph_->warnings.push_back(message);
}

}  // namespace vrflow::daemon
