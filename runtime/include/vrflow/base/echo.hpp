#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace vrflow {

/// The most bytes of a user's value that a message quotes; a longer value is cut there.
inline constexpr std::size_t kMaxEchoedBytes = 100;
/// The most bytes of one message (a diagnostic or an error) before it is cut.
inline constexpr std::size_t kMaxMessageBytes = 4096;

/// `value` cut after kMaxEchoedBytes (at a UTF-8 character boundary) with its whole length
/// noted, as in aaaa…(100000 bytes): for values a message shows without quotes (a list of ids).
std::string shortenedValue(std::string_view value);

/// `value` as a message quotes it: in single quotes, cut after kMaxEchoedBytes (at a UTF-8
/// character boundary) with its whole length noted, as in 'aaaa…(100000 bytes)'.
std::string quotedValue(std::string_view value);

/// `message` with every quoted span ('...') longer than kMaxEchoedBytes cut as quotedValue() does,
/// and the whole cut after kMaxMessageBytes with its length noted: the net under every
/// diagnostic, so that no value a user wrote is echoed whole however a message quotes it.
std::string boundMessage(std::string_view message);

}  // namespace vrflow
