#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/package.hpp"
#include "vrflow/daemon/filter.hpp"

// A filter type is declared once, beside its implementation: a FilterSpec holds what the catalog
// knows of it (validation, the editor's palette) and the factory the daemon builds it with
// (docs/filters.md, "Writing a filter").

namespace vrflow::daemon {

/// One filter type: its declaration (name, doc, parameters with type, range and default, ports,
/// start-up messages, rules over the parameters) and its factory.
struct FilterSpec {
  app::FilterType declaration;
  FilterFactory factory;
  /// False for the daemon's own per-port filters (port-input, port-output): an application
  /// cannot name them, so the catalog does not list them.
  bool inCatalog = true;

  /// The type's name.
  const std::string& name() const { return declaration.name; }
};

/// A declaration with a name, its documentation and its ports (add parameters after).
app::FilterType filterType(
    std::string name, std::string doc,
    std::function<std::vector<app::PortSpec>(const std::vector<app::Param>&)> ports);

/// Gives `type` an int parameter `inputs` (N, default 2) and the ports in0..in{N-1}, each
/// documented `inputDoc`, then `out`, documented `outputDoc`: a filter joining N inputs.
void declareNumberedInputs(app::FilterType& type, const std::string& inputDoc,
                           const std::string& outputDoc);

/// Most inputs or outputs a filter with a numbered port family may have.
inline constexpr long long kMaxFilterPorts = 256;
/// Most initial messages one filter or module input may emit at start-up.
inline constexpr long long kMaxInitialMessages = 1'000'000;

/// A filter port; inputs are required (a filter with an unconnected input never fires).
app::PortSpec filterPort(std::string name, bool isInput, std::string doc);
/// `prefix`0 .. `prefix`{count-1}.
std::vector<app::PortSpec> numberedPorts(const std::string& prefix, long long count, bool isInput,
                                         const std::string& doc);
/// Ports `in` -> `out`.
std::vector<app::PortSpec> inToOut(const std::vector<app::Param>& params);

/// An int parameter in [min, max].
app::ParamSpec intParam(std::string name, std::string defaultValue, double min, double max,
                        std::string doc);
/// A float parameter in [min, max].
app::ParamSpec floatParam(std::string name, std::string defaultValue, double min, double max,
                          std::string doc);
/// A bool parameter ("true" or "false").
app::ParamSpec boolParam(std::string name, std::string defaultValue, std::string doc);
/// An enum parameter; the first choice is the default.
app::ParamSpec enumParam(std::string name, std::vector<std::string> choices, std::string doc);
/// A string parameter.
app::ParamSpec stringParam(std::string name, std::string defaultValue, std::string doc);
/// The value of int parameter `spec` in `params` (its default when absent or unreadable),
/// clamped to the spec's range.
long long clampedInt(const app::ParamSpec& spec, const std::vector<app::Param>& params);
/// The text of `spec` in a filter's file parameters, or its declared default: what a type's
/// `ports` and `check` read before validation, so that the default stays written once.
std::string declaredText(const app::ParamSpec& spec, const std::vector<app::Param>& params);

/// Parameter `stamps` of the merging filters (merge, gather), and its check.
app::ParamSpec stampsParam();
std::optional<std::string> checkStamps(const std::vector<app::Param>& params);

}  // namespace vrflow::daemon
