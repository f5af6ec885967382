#include "vrflow/app/model.hpp"

#include <algorithm>
#include <filesystem>

#include "enum_names.hpp"
#include "text_util.hpp"

namespace vrflow::app {
namespace {

template <typename Items>
auto findById(Items& items, std::string_view id) -> decltype(&items.front()) {
  const auto it =
      std::find_if(items.begin(), items.end(), [&](const auto& item) { return item.id == id; });
  return it == items.end() ? nullptr : &*it;
}

constexpr detail::EnumName<QueuePolicy> kQueuePolicyNames[] = {
    {QueuePolicy::Block, "block"},
    {QueuePolicy::DropOldest, "drop-oldest"},
    {QueuePolicy::DropNewest, "drop-newest"}};
constexpr detail::EnumName<InputMode> kInputModeNames[] = {{InputMode::Fifo, "fifo"},
                                                           {InputMode::Latest, "latest"}};
constexpr detail::EnumName<EndItTiming> kEndItTimingNames[] = {
    {EndItTiming::AfterIteration, "after-iteration"}, {EndItTiming::AfterWait, "after-wait"}};

}  // namespace

const Module* findModule(const Application& app, std::string_view id) {
  return findById(app.modules, id);
}
Module* findModule(Application& app, std::string_view id) {
  return findById(app.modules, id);
}
const Filter* findFilter(const Application& app, std::string_view id) {
  return findById(app.filters, id);
}
Filter* findFilter(Application& app, std::string_view id) {
  return findById(app.filters, id);
}
const Host* findHost(const Application& app, std::string_view id) {
  return findById(app.hosts, id);
}

const EditorNode* findEditorNode(const Application& app, std::string_view ref) {
  const auto it = std::find_if(app.editor.begin(), app.editor.end(),
                               [&](const EditorNode& node) { return node.ref == ref; });
  return it == app.editor.end() ? nullptr : &*it;
}

const SectionComments* findSectionComments(const Application& app, std::string_view section) {
  const auto it =
      std::find_if(app.sectionComments.begin(), app.sectionComments.end(),
                   [&](const SectionComments& comments) { return comments.section == section; });
  return it == app.sectionComments.end() ? nullptr : &*it;
}

const InputConfig* findInputConfig(const Module& module, std::string_view port) {
  const auto it = std::find_if(module.inputs.begin(), module.inputs.end(),
                               [&](const InputConfig& input) { return input.port == port; });
  return it == module.inputs.end() ? nullptr : &*it;
}

InputConfig inputConfigOrDefault(const Module& module, std::string_view port) {
  if (const InputConfig* config = findInputConfig(module, port)) return *config;
  InputConfig config;
  config.port = std::string(port);
  return config;
}

const Param* findParam(const std::vector<Param>& params, std::string_view name) {
  const auto it = std::find_if(params.begin(), params.end(),
                               [&](const Param& param) { return param.name == name; });
  return it == params.end() ? nullptr : &*it;
}

std::string paramString(const std::vector<Param>& params, std::string_view name,
                        std::string_view fallback) {
  const Param* param = findParam(params, name);
  return param ? param->value : std::string(fallback);
}

long long paramInt(const std::vector<Param>& params, std::string_view name, long long fallback) {
  const Param* param = findParam(params, name);
  if (!param) return fallback;
  return detail::parseInteger(param->value).value_or(fallback);
}

double paramFloat(const std::vector<Param>& params, std::string_view name, double fallback) {
  const Param* param = findParam(params, name);
  if (!param) return fallback;
  return detail::parseFloat(param->value).value_or(fallback);
}

bool paramBool(const std::vector<Param>& params, std::string_view name, bool fallback) {
  const Param* param = findParam(params, name);
  if (!param) return fallback;
  return detail::parseBool(param->value).value_or(fallback);
}

std::vector<std::string> splitList(std::string_view text) {
  std::vector<std::string> items;
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    std::string_view item = text.substr(0, comma);
    while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
    if (!item.empty()) items.emplace_back(item);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return items;
}

std::optional<std::vector<StampRule>> parseStampRules(std::string_view text, std::string& problem) {
  std::vector<StampRule> rules;
  for (const std::string& item : splitList(text)) {
    const std::size_t colon = item.rfind(':');
    StampRule rule;
    rule.name = item.substr(0, colon == std::string::npos ? 0 : colon);
    while (!rule.name.empty() && rule.name.back() == ' ') rule.name.pop_back();
    std::string_view how =
        colon == std::string::npos ? std::string_view() : std::string_view(item).substr(colon + 1);
    while (!how.empty() && how.front() == ' ') how.remove_prefix(1);
    if (how == "first") {
      rule.combine = StampCombine::First;
    } else if (how == "sum") {
      rule.combine = StampCombine::Sum;
    } else if (how == "min") {
      rule.combine = StampCombine::Min;
    } else if (how == "max") {
      rule.combine = StampCombine::Max;
    } else {
      problem =
          "'stamps': '" + item +
          "' is not name:first, name:sum, name:min or name:max (a user stamp's name, then how "
          "to combine it)";
      return std::nullopt;
    }
    if (rule.name.empty()) {
      problem = "'stamps': '" + item + "' has no stamp name before ':'";
      return std::nullopt;
    }
    for (const StampRule& other : rules) {
      if (other.name == rule.name) {
        problem = "'stamps': stamp '" + rule.name + "' is listed twice";
        return std::nullopt;
      }
    }
    rules.push_back(std::move(rule));
  }
  return rules;
}

void setParam(std::vector<Param>& params, std::string_view name, std::string value) {
  for (Param& param : params) {
    if (param.name == name) {
      param.value = std::move(value);
      return;
    }
  }
  Param param;
  param.name = std::string(name);
  param.value = std::move(value);
  params.push_back(std::move(param));
}

std::string toString(const Endpoint& endpoint) {
  return endpoint.node + "." + endpoint.port;
}

std::optional<Endpoint> parseEndpoint(std::string_view text) {
  const std::size_t dot = text.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 == text.size()) return std::nullopt;
  return Endpoint{std::string(text.substr(0, dot)), std::string(text.substr(dot + 1))};
}

std::string toString(QueuePolicy policy) {
  return detail::nameOf(kQueuePolicyNames, policy, "block");
}

std::optional<QueuePolicy> parseQueuePolicy(std::string_view text) {
  return detail::valueNamed(kQueuePolicyNames, text);
}

std::string toString(InputMode mode) {
  return detail::nameOf(kInputModeNames, mode, "fifo");
}

std::optional<InputMode> parseInputMode(std::string_view text) {
  return detail::valueNamed(kInputModeNames, text);
}

std::string toString(EndItTiming timing) {
  return detail::nameOf(kEndItTimingNames, timing, "after-iteration");
}

std::optional<EndItTiming> parseEndItTiming(std::string_view text) {
  return detail::valueNamed(kEndItTimingNames, text);
}

std::string effectiveHost(const Application& app, const std::string& host) {
  if (!host.empty() || app.hosts.empty()) return host;
  return app.hosts.front().id;
}

std::string packageFolderPath(const Application& app, const PackageFolder& folder) {
  const std::filesystem::path path(folder.path);
  if (path.is_absolute() || app.file.empty()) return folder.path;
  return (std::filesystem::path(app.file).parent_path() / path).lexically_normal().string();
}

}  // namespace vrflow::app
