#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace vrflow::app::detail {

/// How the XML formats spell one value of an enum.
template <typename Enum>
struct EnumName {
  Enum value;
  std::string_view name;
};

/// The spelling of `value` in `names`, or `fallback` for a value `names` leaves out.
template <typename Enum, std::size_t N>
std::string nameOf(const EnumName<Enum> (&names)[N], Enum value, std::string_view fallback) {
  for (const EnumName<Enum>& entry : names) {
    if (entry.value == value) return std::string(entry.name);
  }
  return std::string(fallback);
}

/// The value `names` spells `text`, or nullopt.
template <typename Enum, std::size_t N>
std::optional<Enum> valueNamed(const EnumName<Enum> (&names)[N], std::string_view text) {
  for (const EnumName<Enum>& entry : names) {
    if (entry.name == text) return entry.value;
  }
  return std::nullopt;
}

}  // namespace vrflow::app::detail
