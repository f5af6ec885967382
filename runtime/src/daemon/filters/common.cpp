#include <algorithm>
#include <variant>

#include "filters.hpp"
#include "vrflow/base/assert.hpp"

namespace vrflow::daemon::filters {

void addBuiltin(FilterRegistry& registry, FilterSpec spec) {
  const Status added = registry.add(std::move(spec));
  VRFLOW_ASSERT(added.ok(), "built-in filter types have distinct names and factories");
}

bool emitInitialMessages(FilterContext& context, long& pending, long& emitted) {
  while (pending > 0 && context.canEmit(0)) {
    auto message = context.makeEmpty(static_cast<uint64_t>(emitted++), false);
    if (!message) {
      context.warn(message.error().message);
      return false;
    }
    context.emit(0, std::move(*message));
    --pending;
  }
  return true;
}

bool allInputsDone(FilterContext& context) {
  for (std::size_t i = 0; i < context.inputCount(); ++i) {
    if (!context.inputClosed(i) || !context.input(i).empty()) return false;
  }
  return true;
}

std::optional<msg::MessageView> viewOrWarn(FilterContext& context, const MessageRef& message) {
  auto view = message.view();
  if (!view) {
    context.warn("filter '" + context.name() +
                 "': dropped a malformed message: " + view.error().message);
    return std::nullopt;
  }
  return *view;
}

namespace {

// The combination of `rule` over the parts' values of that stamp; nullopt when no part has a
// numeric one. Integers stay integers unless a part holds a float.
std::optional<std::variant<std::int64_t, double, std::string>> combine(
    const app::StampRule& rule, const std::vector<msg::MessageView>& views) {
  bool any = false, allInt = true;
  std::int64_t intValue = 0;
  double floatValue = 0.0;
  for (const auto& view : views) {
    const auto stamp = view.stamps().user.find(rule.name);
    if (!stamp) continue;
    const auto asInt = stamp->asInt64();
    const auto asFloat =
        asInt ? std::optional<double>(static_cast<double>(*asInt)) : stamp->asDouble();
    if (!asFloat) continue;
    if (!asInt) allInt = false;
    if (!any) {
      intValue = asInt.value_or(0);
      floatValue = *asFloat;
      any = true;
      continue;
    }
    switch (rule.combine) {
      case app::StampCombine::Sum:
        intValue += asInt.value_or(0);
        floatValue += *asFloat;
        break;
      case app::StampCombine::Min:
        intValue = std::min(intValue, asInt.value_or(intValue));
        floatValue = std::min(floatValue, *asFloat);
        break;
      case app::StampCombine::Max:
        intValue = std::max(intValue, asInt.value_or(intValue));
        floatValue = std::max(floatValue, *asFloat);
        break;
      case app::StampCombine::First:
        break;
    }
  }
  if (!any) return std::nullopt;
  if (allInt) return intValue;
  return floatValue;
}

}  // namespace

Result<MessageRef> join(FilterContext& context, std::span<const MessageRef> parts,
                        const std::vector<app::StampRule>& rules) {
  std::size_t total = 128;
  std::vector<msg::MessageView> views;
  views.reserve(parts.size());
  for (const auto& part : parts) {
    auto view = part.view();
    if (!view) {
      return makeError("filter '" + context.name() +
                       "': malformed message: " + view.error().message);
    }
    views.push_back(*view);
    total += part.size();
  }
  if (views.empty()) return makeError("filter '" + context.name() + "': nothing to join");
  // A traced run draws an arrow from every part of a joined message (the daemon's nodes only).
  context.recordMerge(views);
  msg::Stamps stamps = views.front().stamps().toStamps();
  for (const auto& view : views) {
    stamps.iteration = std::max(stamps.iteration, view.stamps().iteration);
    stamps.simTime = std::max(stamps.simTime, view.stamps().simTime);
  }
  for (const app::StampRule& rule : rules) {
    if (rule.combine == app::StampCombine::First) continue;
    const auto value = combine(rule, views);
    if (!value) continue;
    const auto found = std::find_if(stamps.user.begin(), stamps.user.end(),
                                    [&](const msg::UserStamp& s) { return s.name == rule.name; });
    if (found != stamps.user.end()) {
      found->value = *value;
    } else {
      stamps.user.push_back({rule.name, *value});
    }
  }
  return context.compose(total + 64 * stamps.user.size(), [&](msg::MessageBuilder& builder) {
    builder.setStamps(stamps);
    for (const auto& view : views) builder.appendChunks(view);
  });
}

Result<MessageRef> restamp(FilterContext& context, const msg::MessageView& message,
                           uint64_t iteration) {
  return context.compose(message.bytes().size() + 64, [&](msg::MessageBuilder& builder) {
    builder.setStamps(message.stamps().toStamps());
    builder.setIteration(iteration);
    builder.setStampsOnly(message.stampsOnly());
    if (!message.stampsOnly()) builder.appendChunks(message);
  });
}

std::optional<uint64_t> HeadIteration::of(FilterContext& context, const MessageRef& message) {
  if (message_.valid() && message_.handle() == message.handle()) return iteration_;
  const auto view = viewOrWarn(context, message);
  if (!view) return std::nullopt;
  message_ = message;
  iteration_ = view->stamps().iteration;
  return iteration_;
}

}  // namespace vrflow::daemon::filters
