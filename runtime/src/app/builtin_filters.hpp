#pragma once

#include <optional>
#include <string>
#include <vector>

#include "vrflow/app/package.hpp"

namespace vrflow::app::detail {

/// The filter types every catalog starts with (docs/filters.md): passthrough, merge, initial,
/// broadcast, then the routing and sampling groups below.
std::vector<FilterType> builtinFilterTypes();
/// multiplex, gate, rotate, unrotate, scatter, gather.
void addRoutingFilterTypes(std::vector<FilterType>& types);
/// latest, maxfrequency, stampfilter, typefilter.
void addSamplingFilterTypes(std::vector<FilterType>& types);
/// repeat, decimate, route.
void addPatternFilterTypes(std::vector<FilterType>& types);

/// Most inputs or outputs a filter with a numbered port family may have.
inline constexpr long long kMaxFilterPorts = 256;

/// A filter port; inputs are required (a filter with an unconnected input never fires).
PortSpec filterPort(std::string name, bool isInput, std::string doc);
/// `prefix`0 .. `prefix`{count-1}.
std::vector<PortSpec> numberedPorts(const std::string& prefix, long long count, bool isInput,
                                    const std::string& doc);
/// The value of an int parameter clamped to [1, kMaxFilterPorts] (bad values: `fallback`).
long long portCount(const std::vector<Param>& params, const char* name, long long fallback);

/// Parameter declarations.
ParamSpec intParam(std::string name, std::string defaultValue, double min, double max,
                   std::string doc);
ParamSpec floatParam(std::string name, std::string defaultValue, double min, double max,
                     std::string doc);
ParamSpec boolParam(std::string name, std::string defaultValue, std::string doc);
ParamSpec enumParam(std::string name, std::vector<std::string> choices, std::string doc);
ParamSpec stringParam(std::string name, std::string defaultValue, std::string doc);
/// Parameter `stamps` of the merging filters (merge, gather), and its check.
ParamSpec stampsParam();
std::optional<std::string> checkStamps(const std::vector<Param>& params);

/// Ports `in` -> `out`.
std::vector<PortSpec> inToOut(const std::vector<Param>& params);

}  // namespace vrflow::app::detail
