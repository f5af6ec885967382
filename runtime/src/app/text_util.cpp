#include "text_util.hpp"

#include <algorithm>
#include <charconv>

#include "vrflow/base/echo.hpp"
#include "vrflow/base/parameters.hpp"

namespace vrflow::app::detail {
namespace {

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbouring characters ("hots" -> "host") each cost 1.
std::size_t editDistance(std::string_view a, std::string_view b) {
  const std::size_t width = b.size() + 1;
  std::vector<std::size_t> d((a.size() + 1) * width);
  const auto at = [&](std::size_t i, std::size_t j) -> std::size_t& { return d[i * width + j]; };
  for (std::size_t i = 0; i <= a.size(); ++i) at(i, 0) = i;
  for (std::size_t j = 0; j <= b.size(); ++j) at(0, j) = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      at(i, j) = std::min({at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        at(i, j) = std::min(at(i, j), at(i - 2, j - 2) + 1);
      }
    }
  }
  return at(a.size(), b.size());
}

}  // namespace

std::string joinNames(const std::vector<std::string>& names, std::size_t limit) {
  if (names.empty()) return "none";
  std::string joined;
  for (std::size_t i = 0; i < names.size() && i < limit; ++i) {
    if (i > 0) joined += ", ";
    joined += shortenedValue(names[i]);  // ids a user wrote: a list of them stays bounded
  }
  if (names.size() > limit) {
    joined += " and " + std::to_string(names.size() - limit) + " more";
  }
  return joined;
}

}  // namespace vrflow::app::detail

namespace vrflow::app {

std::optional<std::string> closestName(std::string_view word,
                                       const std::vector<std::string>& candidates) {
  // Long inputs are not typos of short names; also keeps the quadratic distance cheap.
  if (word.empty() || word.size() > 64) return std::nullopt;
  std::optional<std::string> best;
  std::size_t bestDistance = 3;
  for (const std::string& candidate : candidates) {
    if (candidate.size() > 64) continue;
    const std::size_t distance = detail::editDistance(word, candidate);
    if (distance < bestDistance && distance * 2 < std::max(word.size(), candidate.size())) {
      best = candidate;
      bestDistance = distance;
    }
  }
  return best;
}

}  // namespace vrflow::app

namespace vrflow::app::detail {

std::string didYouMean(std::string_view word, const std::vector<std::string>& candidates) {
  const auto closest = closestName(word, candidates);
  return closest ? "; did you mean " + quotedValue(*closest) + "?" : std::string();
}

std::string formatNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::optional<long long> parseInteger(std::string_view text) {
  const Result<ParamValue> value = vrflow::parseParamValue(ParamType::Int, text);
  if (!value) return std::nullopt;
  return std::get<int64_t>(*value);
}

std::optional<double> parseFloat(std::string_view text) {
  const Result<ParamValue> value = vrflow::parseParamValue(ParamType::Float, text);
  if (!value) return std::nullopt;
  return std::get<double>(*value);
}

std::optional<bool> parseBool(std::string_view text) {
  const Result<ParamValue> value = vrflow::parseParamValue(ParamType::Bool, text);
  if (!value) return std::nullopt;
  return std::get<bool>(*value);
}

std::optional<char> firstControlCharacter(std::string_view text) {
  for (const char c : text) {
    if (static_cast<unsigned char>(c) < 0x20U || c == '\x7F') return c;
  }
  return std::nullopt;
}

std::string escapeControlCharacters(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char c : text) {
    if (c == '\n') {
      escaped += "\\n";
    } else if (c == '\r') {
      escaped += "\\r";
    } else if (c == '\t') {
      escaped += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20U || c == '\x7F') {
      static constexpr char kHex[] = "0123456789ABCDEF";
      const auto byte = static_cast<unsigned char>(c);
      escaped += "\\x";
      escaped += kHex[byte >> 4U];
      escaped += kHex[byte & 0xFU];
    } else {
      escaped += c;
    }
  }
  return escaped;
}

std::optional<std::string> hostAddressProblem(std::string_view address) {
  if (address.empty()) return "is empty";
  std::vector<std::string_view> labels;
  for (std::size_t start = 0;;) {
    const std::size_t dot = address.find('.', start);
    labels.push_back(address.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  const auto allDigits = [](std::string_view label) {
    return !label.empty() &&
           std::all_of(label.begin(), label.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (allDigits(labels.back())) {
    // Written as an IPv4 address: it must be one.
    const bool valid = labels.size() == 4 && std::all_of(labels.begin(), labels.end(), [&](auto l) {
                         return allDigits(l) && l.size() <= 3 && std::stoi(std::string(l)) <= 255;
                       });
    if (valid) return std::nullopt;
    return "is not a valid IPv4 address (four numbers 0-255 separated by dots)";
  }
  if (address.size() > 253) return "is not a valid host name (more than 253 characters)";
  for (const std::string_view label : labels) {
    const bool valid = !label.empty() && label.size() <= 63 && label.front() != '-' &&
                       label.back() != '-' && std::all_of(label.begin(), label.end(), [](char c) {
                         return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                                (c >= '0' && c <= '9') || c == '-';
                       });
    if (!valid) {
      return "is neither an IPv4 address nor a valid host name (letters, digits and '-' in "
             "dot-separated labels)";
    }
  }
  return std::nullopt;
}

}  // namespace vrflow::app::detail
