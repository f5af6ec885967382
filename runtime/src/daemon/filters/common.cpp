#include "filters.hpp"

namespace vrflow::daemon::filters {

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
