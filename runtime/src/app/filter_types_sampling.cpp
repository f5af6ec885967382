// Catalog declarations of the sampling and selecting filters: latest, maxfrequency,
// stampfilter, typefilter (docs/filters.md). Implementations: src/daemon/filters/.
#include <algorithm>
#include <string>

#include "builtin_filters.hpp"

namespace vrflow::app::detail {
namespace {

constexpr long long kMaxInitialSync = 1000000;

FilterType latest() {
  FilterType type;
  type.name = "latest";
  type.doc =
      "Greedy sampling: keeps only the newest message of in (older ones are dropped at once, "
      "so the producer never waits), and forwards it on out for each message of sync.";
  type.params.push_back(intParam("initial-sync", "1", 0, static_cast<double>(kMaxInitialSync),
                                 "sync messages assumed received at start-up (starts the "
                                 "reader -> sync cycle)"));
  type.params.push_back(boolParam("repeat", "false",
                                  "answer a sync with the last forwarded message again when "
                                  "nothing newer came (else the sync waits for one)"));
  type.ports = [](const std::vector<Param>&) {
    return std::vector<PortSpec>{filterPort("in", true, "messages to sample"),
                                 filterPort("sync", true, "one message per wanted sample"),
                                 filterPort("out", false, "the newest message, once per sync")};
  };
  type.initialMessages = [](const std::vector<Param>& params) {
    return static_cast<int>(std::clamp(paramInt(params, "initial-sync", 1), 0LL, kMaxInitialSync));
  };
  return type;
}

FilterType maxFrequency() {
  FilterType type;
  type.name = "maxfrequency";
  type.doc =
      "Forwards in to out at most `frequency` times per second: two messages leave at least "
      "1/frequency s apart. `wait` holds early messages (the producer is paced); `latest` "
      "drops all but the newest pending one.";
  type.params.push_back(floatParam("frequency", "30", 0.001, 1e6, "most messages per second"));
  type.params.push_back(enumParam("mode", {"wait", "latest"}, "what happens to early messages"));
  type.ports = inToOut;
  return type;
}

FilterType stampFilter() {
  FilterType type;
  type.name = "stampfilter";
  type.doc =
      "For each message of order, forwards the message of in whose iteration stamp it names "
      "(its integer user stamp `stamp`, else its own iteration stamp); older messages of in "
      "are dropped, an order whose message is gone is skipped.";
  type.params.push_back(
      stringParam("stamp", "iteration", "the order's integer user stamp that names the iteration"));
  type.ports = [](const std::vector<Param>&) {
    return std::vector<PortSpec>{filterPort("in", true, "candidate messages, by iteration"),
                                 filterPort("order", true, "which iteration to forward next"),
                                 filterPort("out", false, "the ordered messages")};
  };
  return type;
}

FilterType typeFilter() {
  FilterType type;
  type.name = "typefilter";
  type.doc =
      "Forwards in to out without the object chunks whose type is not listed in `types`; "
      "resource and event chunks pass unless drop-others. A message whose chunks all go "
      "still leaves (empty), so the consumer keeps its rate.";
  type.params.push_back(stringParam("types", "", "object type names to keep, comma-separated"));
  type.params.push_back(boolParam("drop-others", "false", "also drop resource and event chunks"));
  type.ports = inToOut;
  type.check = [](const std::vector<Param>& params) -> std::optional<std::string> {
    if (splitList(paramString(params, "types", "")).empty()) {
      return "parameter 'types' must list at least one object type name (e.g. \"rigid, "
             "point\")";
    }
    return std::nullopt;
  };
  return type;
}

}  // namespace

void addSamplingFilterTypes(std::vector<FilterType>& types) {
  types.push_back(latest());
  types.push_back(maxFrequency());
  types.push_back(stampFilter());
  types.push_back(typeFilter());
}

}  // namespace vrflow::app::detail
