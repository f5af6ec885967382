#include "template_text.hpp"

#include <cctype>
#include <climits>
#include <vector>

#include "text_util.hpp"
#include "vrflow/base/echo.hpp"

namespace vrflow::app::detail {
namespace {

bool isNameStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_';
}

bool isNameChar(char c) {
  return isNameStart(c) || std::isdigit(static_cast<unsigned char>(c)) != 0;
}

// A recursive-descent parser over one expression. Nesting depth is bounded so that a hostile
// "((((..." cannot overflow the stack.
class ExpressionParser {
 public:
  ExpressionParser(std::string_view text, const TemplateScope& scope)
      : text_(text), scope_(scope) {}

  Result<long long> parse() {
    const long long value = sum();
    skipSpace();
    if (error_.empty() && pos_ < text_.size()) {
      fail("unexpected '" + std::string(1, text_[pos_]) + "'");
    }
    if (!error_.empty()) return makeError(error_);
    return value;
  }

 private:
  static constexpr int kMaxDepth = 64;

  void skipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_])) != 0) {
      ++pos_;
    }
  }

  bool accept(char c) {
    skipSpace();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }

  void fail(std::string message) {
    if (error_.empty()) error_ = std::move(message);
  }

  long long overflowed() {
    fail("the result does not fit in 64 bits");
    return 0;
  }

  long long sum() {
    long long value = product();
    while (error_.empty()) {
      const bool add = accept('+');
      if (!add && !accept('-')) break;
      const long long operand = product();
      const bool overflow = add ? __builtin_add_overflow(value, operand, &value)
                                : __builtin_sub_overflow(value, operand, &value);
      if (overflow) return overflowed();
    }
    return value;
  }

  long long product() {
    long long value = unary();
    while (error_.empty()) {
      if (accept('*')) {
        const long long operand = unary();
        if (__builtin_mul_overflow(value, operand, &value)) return overflowed();
      } else if (accept('/') || accept('%')) {
        const bool divide = text_[pos_ - 1] == '/';
        const long long divisor = unary();
        if (divisor == 0) {
          fail("division by zero");
          return 0;
        }
        if (value == LLONG_MIN && divisor == -1) return overflowed();
        value = divide ? value / divisor : value % divisor;
      } else {
        break;
      }
    }
    return value;
  }

  long long unary() {
    if (++depth_ > kMaxDepth) {
      fail("nested too deeply");
      return 0;
    }
    long long value = 0;
    if (accept('-')) {
      const long long operand = unary();
      if (operand == LLONG_MIN) return overflowed();
      value = -operand;
    } else {
      value = primary();
    }
    --depth_;
    return value;
  }

  long long primary() {
    skipSpace();
    if (accept('(')) {
      const long long value = sum();
      if (!accept(')')) fail("missing ')'");
      return value;
    }
    const std::size_t start = pos_;
    if (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])) != 0) {
      while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])) != 0) {
        ++pos_;
      }
      const auto value = parseInteger(text_.substr(start, pos_ - start));
      if (!value)
        fail("the number " + std::string(text_.substr(start, pos_ - start)) +
             " does not fit in 64 bits");
      return value.value_or(0);
    }
    if (pos_ < text_.size() && isNameStart(text_[pos_])) {
      while (pos_ < text_.size() && isNameChar(text_[pos_])) ++pos_;
      return name(text_.substr(start, pos_ - start));
    }
    fail(pos_ < text_.size() ? "unexpected '" + std::string(1, text_[pos_]) + "'"
                             : "an operand is missing");
    return 0;
  }

  long long name(std::string_view name) {
    const auto it = scope_.find(name);
    if (it == scope_.end()) {
      std::vector<std::string> known;
      for (const auto& entry : scope_) known.push_back(entry.first);
      fail("unknown name '" + std::string(name) + "' (known: " + joinNames(known) + ")" +
           didYouMean(name, known));
      return 0;
    }
    const auto value = parseInteger(it->second);
    if (!value) fail("'" + std::string(name) + "' is '" + it->second + "', not an integer");
    return value.value_or(0);
  }

  std::string_view text_;
  const TemplateScope& scope_;
  std::size_t pos_ = 0;
  int depth_ = 0;
  std::string error_;
};

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())) != 0) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())) != 0) {
    text.remove_suffix(1);
  }
  return text;
}

}  // namespace

bool isTemplateName(std::string_view text) {
  if (text.empty() || !isNameStart(text.front())) return false;
  for (const char c : text) {
    if (!isNameChar(c)) return false;
  }
  return true;
}

Result<long long> evaluateExpression(std::string_view expression, const TemplateScope& scope) {
  return ExpressionParser(expression, scope).parse();
}

Result<std::string> substituteTemplate(std::string_view text, const TemplateScope& scope) {
  std::string out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t dollar = text.find('$', pos);
    if (dollar == std::string_view::npos || dollar + 1 == text.size()) {
      out.append(text.substr(pos));
      break;
    }
    out.append(text.substr(pos, dollar - pos));
    const char next = text[dollar + 1];
    if (next == '$') {
      out += '$';
      pos = dollar + 2;
      continue;
    }
    if (next != '{') {
      out += '$';
      pos = dollar + 1;
      continue;
    }
    const std::size_t close = text.find('}', dollar + 2);
    if (close == std::string_view::npos) {
      return makeError("'${' without a closing '}' in " + quotedValue(text));
    }
    const std::string_view inner = trimmed(text.substr(dollar + 2, close - dollar - 2));
    const std::string written = quotedValue(text.substr(dollar, close + 1 - dollar));
    if (isTemplateName(inner)) {
      const auto it = scope.find(inner);
      if (it == scope.end()) {
        std::vector<std::string> known;
        for (const auto& [name, value] : scope) known.push_back(name);
        return makeError("unknown name '" + std::string(inner) + "' in " + written +
                         " (known: " + joinNames(known) + ")" + didYouMean(inner, known));
      }
      out += it->second;
    } else {
      const Result<long long> value = evaluateExpression(inner, scope);
      if (!value) return makeError("cannot evaluate " + written + ": " + value.error().message);
      out += std::to_string(*value);
    }
    pos = close + 1;
  }
  return out;
}

}  // namespace vrflow::app::detail
