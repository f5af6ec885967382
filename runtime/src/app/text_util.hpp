#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/app/closest_name.hpp"

namespace vrflow::app::detail {

/// "a, b, c" (at most `limit` names, then "and N more"); "none" when empty.
std::string joinNames(const std::vector<std::string>& names, std::size_t limit = 12);

using app::closestName;  // vrflow/app/closest_name.hpp

/// "; did you mean 'x'?" when a close candidate exists, else "".
std::string didYouMean(std::string_view word, const std::vector<std::string>& candidates);

/// The shortest text that reads back as `value` ("10", "0.5", "1e+20").
std::string formatNumber(double value);

/// Parses a whole string as a decimal integer (optional '-'), or nullopt (parseParamValue).
std::optional<long long> parseInteger(std::string_view text);
/// Parses a whole string as a finite decimal float, or nullopt.
std::optional<double> parseFloat(std::string_view text);
/// Parses "true"/"false"/"1"/"0" (xs:boolean), or nullopt.
std::optional<bool> parseBool(std::string_view text);

/// The first control character (below U+0020, or U+007F) in `text`, or nullopt.
std::optional<char> firstControlCharacter(std::string_view text);
/// `text` with its control characters written as C escapes ("\n", "\x01"), for messages.
std::string escapeControlCharacters(std::string_view text);
/// Why `address` is neither an IPv4 address (a.b.c.d, each 0-255) nor a host name (RFC 1123:
/// dot-separated labels of letters, digits and '-', 1-63 characters, not starting or ending
/// with '-', 253 characters at most, the last label not all digits), or nullopt.
std::optional<std::string> hostAddressProblem(std::string_view address);

}  // namespace vrflow::app::detail
