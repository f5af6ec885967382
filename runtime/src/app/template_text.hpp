#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "vrflow/base/result.hpp"

namespace vrflow::app::detail {

/// The names `${...}` can use while a composite is expanded: its parameters and the variables
/// of the enclosing <repeat> elements, with their values as text.
using TemplateScope = std::map<std::string, std::string, std::less<>>;

/// True for a name `${...}` can use: a letter or '_', then letters, digits and '_'.
bool isTemplateName(std::string_view text);

/// Replaces every `${...}` of `text`: `${name}` by the value of `name` as it is (any text),
/// any other `${expression}` by the decimal value of the integer expression. `$$` writes one
/// '$'; any other '$' is kept. The error message says what is wrong, quoting the `${...}`.
Result<std::string> substituteTemplate(std::string_view text, const TemplateScope& scope);

/// The value of an integer expression: decimal integers, names whose value is an integer,
/// unary '-', '+' '-' '*' '/' '%' with the usual precedence, parentheses. '/' and '%' round
/// toward zero (as in C). Overflow of 64 bits and division by zero are errors.
Result<long long> evaluateExpression(std::string_view expression, const TemplateScope& scope);

}  // namespace vrflow::app::detail
