#include "vrflow/base/parameters.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <vector>

#include "vrflow/base/assert.hpp"

namespace vrflow {
namespace {

std::optional<int64_t> parseInteger(std::string_view text) {
  int64_t value = 0;
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  if (text.empty() || result.ec != std::errc() || result.ptr != end) return std::nullopt;
  return value;
}

std::optional<double> parseFloat(std::string_view text) {
  double value = 0;
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value, std::chars_format::general);
  if (text.empty() || result.ec != std::errc() || result.ptr != end || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// Three words separated by spaces and/or commas, or nullopt.
std::optional<std::vector<std::string_view>> splitVec3(std::string_view text) {
  std::vector<std::string_view> parts;
  std::size_t p = 0;
  const auto isSeparator = [](char c) {
    return c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  };
  while (p < text.size()) {
    while (p < text.size() && isSeparator(text[p])) ++p;
    const std::size_t start = p;
    while (p < text.size() && !isSeparator(text[p])) ++p;
    if (p > start) parts.push_back(text.substr(start, p - start));
    if (parts.size() > 3) return std::nullopt;
  }
  if (parts.size() != 3) return std::nullopt;
  return parts;
}

// The alternative of ParamValue that a parameter of `type` holds.
std::size_t alternativeOf(ParamType type) {
  switch (type) {
    case ParamType::Int:
      return 0;
    case ParamType::Float:
      return 1;
    case ParamType::Bool:
      return 2;
    case ParamType::Vec3:
      return 4;
    case ParamType::String:
    case ParamType::Enum:
    case ParamType::File:
      return 3;
  }
  return 3;
}

// A little-endian-agnostic byte writer and reader: the set never leaves the host.
template <typename T>
void put(std::string& out, const T& value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

void putText(std::string& out, std::string_view text) {
  put(out, static_cast<uint32_t>(text.size()));
  out.append(text);
}

class ByteReader {
 public:
  explicit ByteReader(std::string_view bytes) : bytes_(bytes) {}
  template <typename T>
  bool get(T& value) {
    if (bytes_.size() < sizeof(T)) return false;
    std::memcpy(&value, bytes_.data(), sizeof(T));
    bytes_.remove_prefix(sizeof(T));
    return true;
  }
  bool getText(std::string& text) {
    uint32_t size = 0;
    if (!get(size) || bytes_.size() < size) return false;
    text.assign(bytes_.substr(0, size));
    bytes_.remove_prefix(size);
    return true;
  }
  bool empty() const { return bytes_.empty(); }

 private:
  std::string_view bytes_;
};

constexpr uint32_t kMagic = 0x31505256;  // "VRP1"

}  // namespace

std::string toString(ParamType type) {
  switch (type) {
    case ParamType::Int:
      return "int";
    case ParamType::Float:
      return "float";
    case ParamType::Bool:
      return "bool";
    case ParamType::String:
      return "string";
    case ParamType::Enum:
      return "enum";
    case ParamType::Vec3:
      return "vec3";
    case ParamType::File:
      return "file";
  }
  return "string";
}

std::optional<ParamType> parseParamType(std::string_view text) {
  for (const ParamType type : {ParamType::Int, ParamType::Float, ParamType::Bool, ParamType::String,
                               ParamType::Enum, ParamType::Vec3, ParamType::File}) {
    if (toString(type) == text) return type;
  }
  return std::nullopt;
}

Result<ParamValue> parseParamValue(ParamType type, std::string_view text) {
  const std::string got = ", got '" + std::string(text) + "'";
  switch (type) {
    case ParamType::Int:
      if (const auto value = parseInteger(text)) return ParamValue(*value);
      return makeError("expects an int" + got);
    case ParamType::Float:
      if (const auto value = parseFloat(text)) return ParamValue(*value);
      return makeError("expects a finite float" + got);
    case ParamType::Bool:
      if (text == "true" || text == "1") return ParamValue(true);
      if (text == "false" || text == "0") return ParamValue(false);
      return makeError("expects a bool (true or false)" + got);
    case ParamType::Vec3: {
      const auto parts = splitVec3(text);
      if (!parts) return makeError("expects 3 numbers 'x y z'" + got);
      ParamVec3 vector{};
      for (std::size_t i = 0; i < 3; ++i) {
        const auto value = parseFloat((*parts)[i]);
        if (!value) return makeError("expects 3 finite numbers 'x y z'" + got);
        vector[i] = *value;
      }
      return ParamValue(vector);
    }
    case ParamType::String:
    case ParamType::Enum:
    case ParamType::File:
      return ParamValue(std::string(text));
  }
  return ParamValue(std::string(text));
}

void Parameters::declare(std::string name, ParamType type, std::optional<ParamValue> value) {
  VRFLOW_ASSERT(!value || value->index() == alternativeOf(type),
                "a parameter's value must have its declared type");
  entries_[std::move(name)] = Entry{type, std::move(value)};
}

bool Parameters::declares(std::string_view name) const {
  return entries_.find(name) != entries_.end();
}

bool Parameters::hasValue(std::string_view name) const {
  const auto it = entries_.find(name);
  return it != entries_.end() && it->second.value.has_value();
}

void Parameters::fail(std::string message) const {
  Error error{(owner_.empty() ? std::string("parameters") : owner_) + ": " + std::move(message)};
  if (failureHandler_ != nullptr) failureHandler_(error);
  if (!firstError_) firstError_ = std::move(error);
}

const ParamValue* Parameters::find(std::string_view name, ParamType type,
                                   std::string_view readAs) const {
  const auto it = entries_.find(name);
  if (it == entries_.end()) {
    std::string declared;
    for (const auto& entry : entries_) declared += (declared.empty() ? "" : ", ") + entry.first;
    fail("reads parameter '" + std::string(name) +
         "', which is not declared (declared: " + (declared.empty() ? "none" : declared) + ")");
    return nullptr;
  }
  const Entry& entry = it->second;
  if (alternativeOf(entry.type) != alternativeOf(type)) {
    fail("reads parameter '" + std::string(name) + "' as " + std::string(readAs) +
         ", but it is declared " + toString(entry.type));
    return nullptr;
  }
  if (!entry.value) {
    fail("parameter '" + std::string(name) +
         "' has no value (the declaration gives no default and the application sets none)");
    return nullptr;
  }
  return &*entry.value;
}

int64_t Parameters::getInt(std::string_view name) const {
  const ParamValue* value = find(name, ParamType::Int, "an int");
  return value != nullptr ? std::get<int64_t>(*value) : 0;
}

double Parameters::getFloat(std::string_view name) const {
  const ParamValue* value = find(name, ParamType::Float, "a float");
  return value != nullptr ? std::get<double>(*value) : 0.0;
}

bool Parameters::getBool(std::string_view name) const {
  const ParamValue* value = find(name, ParamType::Bool, "a bool");
  return value != nullptr && std::get<bool>(*value);
}

std::string Parameters::getString(std::string_view name) const {
  const ParamValue* value = find(name, ParamType::String, "text (string, enum or file)");
  return value != nullptr ? std::get<std::string>(*value) : std::string();
}

ParamVec3 Parameters::getVec3(std::string_view name) const {
  const ParamValue* value = find(name, ParamType::Vec3, "a vec3");
  return value != nullptr ? std::get<ParamVec3>(*value) : ParamVec3{};
}

std::string encodeParameters(const Parameters& parameters) {
  std::string out;
  put(out, kMagic);
  putText(out, parameters.owner());
  put(out, static_cast<uint32_t>(parameters.entries().size()));
  for (const auto& [name, entry] : parameters.entries()) {
    putText(out, name);
    put(out, static_cast<uint8_t>(entry.type));
    put(out, static_cast<uint8_t>(entry.value ? 1 : 0));
    if (!entry.value) continue;
    std::visit(
        [&out](const auto& value) {
          using T = std::decay_t<decltype(value)>;
          if constexpr (std::is_same_v<T, std::string>) {
            putText(out, value);
          } else if constexpr (std::is_same_v<T, bool>) {
            put(out, static_cast<uint8_t>(value ? 1 : 0));
          } else {
            put(out, value);
          }
        },
        *entry.value);
  }
  return out;
}

Result<Parameters> decodeParameters(std::string_view bytes) {
  const auto corrupt = [](const std::string& what) {
    return makeError("the parameter block is corrupt (" + what + ")");
  };
  ByteReader in(bytes);
  uint32_t magic = 0;
  if (!in.get(magic) || magic != kMagic) return corrupt("no header");
  std::string owner;
  uint32_t count = 0;
  if (!in.getText(owner) || !in.get(count)) return corrupt("truncated header");
  Parameters parameters(std::move(owner));
  for (uint32_t i = 0; i < count; ++i) {
    std::string name;
    uint8_t typeCode = 0;
    uint8_t hasValue = 0;
    if (!in.getText(name) || !in.get(typeCode) || !in.get(hasValue)) {
      return corrupt("truncated entry");
    }
    if (typeCode > static_cast<uint8_t>(ParamType::File) || hasValue > 1) {
      return corrupt("parameter '" + name + "'");
    }
    const auto type = static_cast<ParamType>(typeCode);
    std::optional<ParamValue> value;
    bool read = true;
    if (hasValue != 0) {
      switch (alternativeOf(type)) {
        case 0: {
          int64_t v = 0;
          read = in.get(v);
          value = v;
          break;
        }
        case 1: {
          double v = 0;
          read = in.get(v);
          value = v;
          break;
        }
        case 2: {
          uint8_t v = 0;
          read = in.get(v) && v <= 1;
          value = v != 0;
          break;
        }
        case 4: {
          ParamVec3 v{};
          read = in.get(v);
          value = v;
          break;
        }
        default: {
          std::string v;
          read = in.getText(v);
          value = std::move(v);
          break;
        }
      }
    }
    if (!read) return corrupt("value of parameter '" + name + "'");
    parameters.declare(std::move(name), type, std::move(value));
  }
  if (!in.empty()) return corrupt("trailing bytes");
  return parameters;
}

}  // namespace vrflow
