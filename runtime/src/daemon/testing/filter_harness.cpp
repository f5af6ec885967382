#include "vrflow/daemon/testing/filter_harness.hpp"

#include <algorithm>

#include "../compose.hpp"
#include "vrflow/base/assert.hpp"
#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::daemon::testing {
namespace {

constexpr std::size_t kSegmentBytes = std::size_t{64} << 20;  // sparse: touched pages only

// What `vrflow validate` says of these parameters of `type`: the first problem, if any.
std::optional<std::string> paramProblem(const app::FilterType& type,
                                        const std::vector<app::Param>& params) {
  for (const app::Param& param : params) {
    const app::ParamSpec* spec = type.findParam(param.name);
    if (spec == nullptr) {
      return "filter type '" + type.name + "' has no parameter '" + param.name + "'";
    }
    if (const auto problem = app::checkParamValue(*spec, param.value)) {
      return "parameter '" + param.name + "' of filter type '" + type.name + "' " + *problem;
    }
  }
  if (type.check) {
    if (const auto problem = type.check(params))
      return "filter type '" + type.name + "': " + *problem;
  }
  return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<FilterHarness>> FilterHarness::create(
    const std::string& type, const std::map<std::string, std::string>& params) {
  const FilterSpec* spec = FilterRegistry::instance().find(type);
  if (spec == nullptr) return makeError("unknown filter type '" + type + "'");
  std::vector<app::Param> given;
  for (const auto& [name, value] : params) given.push_back(app::Param{name, value, {}});
  if (const auto problem = paramProblem(spec->declaration, given)) return makeError(*problem);
  // As the daemon does: typed once, the given values over the declared defaults.
  auto values =
      app::parameterSet(spec->declaration.params, given, "filter '" + type + "' (" + type + ")");
  if (!values) return values.error();

  auto segment = ipc::Segment::create(kSegmentBytes);
  if (!segment) return segment.error();
  std::unique_ptr<FilterHarness> harness(new FilterHarness(
      std::move(*segment), type, std::move(*values), spec->declaration.portsFor(given)));
  auto filter = spec->factory(*harness);
  if (!filter) return filter.error();
  if (const auto& misread = harness->params_.firstError()) return *misread;
  harness->filter_ = std::move(*filter);
  if (auto started = harness->filter_->start(*harness); !started) return started.error();
  if (const auto& misread = harness->params_.firstError()) return *misread;
  return harness;
}

FilterHarness::FilterHarness(ipc::Segment segment, std::string type, Parameters params,
                             const std::vector<app::PortSpec>& ports)
    : segment_(std::move(segment)), name_(std::move(type)), params_(std::move(params)) {
  for (const app::PortSpec& port : ports) {
    (port.isInput ? inputNames_ : outputNames_).push_back(port.name);
  }
  inputs_.resize(inputNames_.size());
  closed_.assign(inputNames_.size(), false);
  dropped_.assign(inputNames_.size(), 0);
  outputs_.resize(outputNames_.size());
  room_.resize(outputNames_.size());
  ended_.assign(outputNames_.size(), false);
}

FilterHarness::~FilterHarness() = default;

MessageRef FilterHarness::message(const std::function<void(msg::MessageBuilder&)>& fill) {
  auto made = composeMessage(segment_, "test", 256, [&](msg::MessageBuilder& builder) {
    if (fill) fill(builder);
  });
  VRFLOW_ASSERT(made.ok(), "the harness's segment holds the test's messages");
  return std::move(*made);
}

MessageRef FilterHarness::stamped(uint64_t iteration) {
  return message([&](msg::MessageBuilder& builder) { builder.setIteration(iteration); });
}

void FilterHarness::push(std::string_view port, MessageRef message) {
  inputs_[inputIndex(port)].push_back(std::move(message));
}

void FilterHarness::close(std::string_view port) {
  closed_[inputIndex(port)] = true;
}

void FilterHarness::step() {
  wakeDelay_.reset();  // a request holds until the next call of process()
  filter_->process(*this);
}

bool FilterHarness::exhausted() {
  return filter_->exhausted(*this);
}

std::vector<MessageRef> FilterHarness::take(std::string_view port) {
  return std::exchange(outputs_[outputIndex(port)], {});
}

std::vector<uint64_t> FilterHarness::takeIterations(std::string_view port) {
  std::vector<uint64_t> iterations;
  for (const MessageRef& message : take(port)) {
    const auto view = message.view();
    VRFLOW_ASSERT(view.ok(), "a filter emits well-formed messages");
    iterations.push_back(view->stamps().iteration);
  }
  return iterations;
}

void FilterHarness::setRoom(std::string_view port, std::size_t room) {
  room_[outputIndex(port)] = room;
}

void FilterHarness::endOutput(std::string_view port) {
  ended_[outputIndex(port)] = true;
}

uint64_t FilterHarness::droppedOn(std::string_view port) const {
  return dropped_[inputIndex(port)];
}

void FilterHarness::countDropped(std::size_t i, uint64_t count, std::string_view /*reason*/) {
  dropped_.at(i) += count;
}

bool FilterHarness::canEmit(std::size_t o) const {
  const auto& room = room_.at(o);
  return !room || *room > 0;
}

void FilterHarness::emit(std::size_t o, MessageRef message) {
  VRFLOW_ASSERT(canEmit(o), "a filter emits only where canEmit() allows it");
  if (auto& room = room_[o]) --*room;
  outputs_[o].push_back(std::move(message));
}

Result<MessageRef> FilterHarness::compose(std::size_t sizeHint,
                                          const std::function<void(msg::MessageBuilder&)>& fill) {
  return composeMessage(segment_, name_, sizeHint, fill);
}

void FilterHarness::wakeAfter(uint64_t delayNs) {
  wakeDelay_ = wakeDelay_ ? std::min(*wakeDelay_, delayNs) : delayNs;
}

std::size_t FilterHarness::inputIndex(std::string_view port) const {
  const auto it = std::find(inputNames_.begin(), inputNames_.end(), port);
  VRFLOW_ASSERT(it != inputNames_.end(), "the filter has this input");
  return static_cast<std::size_t>(it - inputNames_.begin());
}

std::size_t FilterHarness::outputIndex(std::string_view port) const {
  const auto it = std::find(outputNames_.begin(), outputNames_.end(), port);
  VRFLOW_ASSERT(it != outputNames_.end(), "the filter has this output");
  return static_cast<std::size_t>(it - outputNames_.begin());
}

}  // namespace vrflow::daemon::testing
