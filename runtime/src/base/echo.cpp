#include "vrflow/base/echo.hpp"

#include <cctype>

namespace vrflow {
namespace {

// The first bytes of `text`, at most `limit`, ending at a UTF-8 character boundary.
std::string_view head(std::string_view text, std::size_t limit) {
  if (text.size() <= limit) return text;
  std::size_t end = limit;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return text.substr(0, end);
}

std::string cut(std::string_view text, std::size_t limit) {
  if (text.size() <= limit) return std::string(text);
  return std::string(head(text, limit)) + "\u2026(" + std::to_string(text.size()) + " bytes)";
}

}  // namespace

std::string shortenedValue(std::string_view value) {
  return cut(value, kMaxEchoedBytes);
}

std::string quotedValue(std::string_view value) {
  return "'" + cut(value, kMaxEchoedBytes) + "'";
}

std::string boundMessage(std::string_view message) {
  // A quote opens a span after a non-word character and closes one before it, so that the
  // apostrophe of "the module's" is not taken for a quote.
  const auto isWord = [&](std::size_t i) {
    return i < message.size() && std::isalnum(static_cast<unsigned char>(message[i])) != 0;
  };
  std::string out;
  std::size_t at = 0;
  for (std::size_t open = message.find('\''); open != std::string_view::npos;
       open = message.find('\'', open + 1)) {
    if (open > 0 && isWord(open - 1)) continue;
    std::size_t close = message.find('\'', open + 1);
    while (close != std::string_view::npos && isWord(close + 1)) {
      close = message.find('\'', close + 1);
    }
    if (close == std::string_view::npos) break;
    out.append(message.substr(at, open - at));
    out += quotedValue(message.substr(open + 1, close - open - 1));
    at = close + 1;
    open = close;
  }
  out.append(message.substr(at));
  if (out.size() <= kMaxMessageBytes) return out;
  return cut(out, kMaxMessageBytes);
}

}  // namespace vrflow
