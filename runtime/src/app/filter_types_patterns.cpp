// Catalog declarations of the network-pattern filters: repeat and decimate (multi-rate), route
// (dynamic routing by bounding volume) (docs/filters.md). Implementations: src/daemon/filters/.
#include <string>

#include "builtin_filters.hpp"

namespace vrflow::app::detail {
namespace {

constexpr double kMaxRepeat = 1000000;

FilterType repeat() {
  FilterType type;
  type.name = "repeat";
  type.doc =
      "Multi-rate input: each message of in leaves count times, copy j with time step dt/count, "
      "simulation time t + j*dt/count and iteration i*count + j, so the module behind it runs "
      "count iterations per message.";
  type.params.push_back(intParam("count", "10", 1, kMaxRepeat, "copies per message (k)"));
  type.ports = inToOut;
  return type;
}

FilterType decimate() {
  FilterType type;
  type.name = "decimate";
  type.doc =
      "Multi-rate output: forwards only the last of every count messages of in. With restamp, "
      "its iteration becomes the group's number and its time step the sum of the group's.";
  type.params.push_back(intParam("count", "10", 1, kMaxRepeat, "messages per group (k)"));
  type.params.push_back(boolParam("restamp", "true",
                                  "iteration = group number, time step = the group's total (a "
                                  "copy); false forwards the message untouched, by reference"));
  type.params.push_back(boolParam("merge", "true",
                                  "the objects and resources of the dropped messages are folded "
                                  "into the forwarded one (an add and later updates become one "
                                  "add), so no state is lost; events of dropped messages are not "
                                  "kept"));
  type.ports = inToOut;
  return type;
}

FilterType route() {
  FilterType type;
  type.name = "route";
  type.doc =
      "Dynamic routing by bounding volume: receiver k publishes its volume of interest on "
      "interest{k} (string user stamp `stamp`: \"minx miny minz maxx maxy maxz\", \"all\" or "
      "\"none\"); out{k} gets the chunks of objects whose bounds meet it, the full state of "
      "an object when it enters, and the resources those objects refer to, once.";
  type.params.push_back(
      intParam("outputs", "1", 1, static_cast<double>(kMaxFilterPorts), "number of receivers N"));
  type.params.push_back(
      stringParam("stamp", "interest", "name of the string user stamp holding the volume"));
  type.params.push_back(enumParam("initially", {"none", "all"},
                                  "the volume of every receiver before its first interest"));
  type.params.push_back(enumParam("unbounded", {"all", "drop"},
                                  "objects whose bounds are unknown: to every receiver that has "
                                  "a volume, or to none"));
  type.ports = [](const std::vector<Param>& params) {
    const long long n = portCount(params, "outputs", 1);
    std::vector<PortSpec> ports{filterPort("in", true, "the sender's messages")};
    for (auto& port : numberedPorts("interest", n, true, "a receiver's volume of interest")) {
      port.gating = false;  // out{k} leaves without it: a receiver -> interest cycle is fine
      ports.push_back(std::move(port));
    }
    for (auto& port : numberedPorts("out", n, false, "what one receiver's volume meets")) {
      ports.push_back(std::move(port));
    }
    return ports;
  };
  type.check = [](const std::vector<Param>& params) -> std::optional<std::string> {
    if (paramString(params, "stamp", "interest").empty()) {
      return "parameter 'stamp' must name a user stamp (e.g. \"interest\")";
    }
    return std::nullopt;
  };
  return type;
}

}  // namespace

void addPatternFilterTypes(std::vector<FilterType>& types) {
  types.push_back(repeat());
  types.push_back(decimate());
  types.push_back(route());
}

}  // namespace vrflow::app::detail
