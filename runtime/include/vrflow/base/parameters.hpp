#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "vrflow/base/result.hpp"

namespace vrflow {

/// The value types of parameters (as manifests and filter specs declare them).
enum class ParamType { Int, Float, Bool, String, Enum, Vec3, File };

/// "int", "float", "bool", "string", "enum", "vec3" or "file".
std::string toString(ParamType type);
/// The type written `text`, or nullopt.
std::optional<ParamType> parseParamType(std::string_view text);

/// Three numbers: a vec3 parameter's value.
using ParamVec3 = std::array<double, 3>;

/// A typed parameter value: int, float, bool, text (string, enum choice, file path) or vec3.
using ParamValue = std::variant<int64_t, double, bool, std::string, ParamVec3>;

/// The one parser from a parameter's text to its typed value: a whole decimal integer (int), a
/// finite float (float), true/false/1/0 (bool), three finite numbers separated by spaces and/or
/// commas (vec3), any text (string, enum, file). On failure the message says what was expected
/// ("expects an int, got 'x'"). Ranges and enum choices are the declaration's business
/// (app::checkParamValue).
Result<ParamValue> parseParamValue(ParamType type, std::string_view text);

/// The typed parameters of one module or filter: each declared name with its type and value,
/// built once from the application's values over the declaration's defaults. Reading a name
/// that is not declared, one declared without a value, or one of another type is an error
/// naming the owner and the parameter: it goes to the failure handler when one is set (a
/// module's prints it and exits non-zero), else it is kept (firstError()) for the caller to
/// report, and the read returns a zero value.
class Parameters {
 public:
  /// Called on a failed read; a module's handler prints the message and exits.
  using FailureHandler = void (*)(const Error& error);

  Parameters() = default;
  /// An empty set owned by `owner` ("module 'm' (core/points)", "filter 'f' (latest)").
  explicit Parameters(std::string owner) : owner_(std::move(owner)) {}

  /// Who the parameters belong to, as error messages name it.
  const std::string& owner() const { return owner_; }
  /// Declares `name` with `type` and its value (nullopt: declared without a value). The value
  /// must hold the alternative that `type` reads as (a bug otherwise).
  void declare(std::string name, ParamType type, std::optional<ParamValue> value);

  /// True when `name` is declared (with or without a value).
  bool declares(std::string_view name) const;
  /// True when `name` is declared with a value.
  bool hasValue(std::string_view name) const;

  /// The value of an int parameter.
  int64_t getInt(std::string_view name) const;
  /// The value of a float parameter.
  double getFloat(std::string_view name) const;
  /// The value of a bool parameter.
  bool getBool(std::string_view name) const;
  /// The text of a string, enum or file parameter.
  std::string getString(std::string_view name) const;
  /// The value of a vec3 parameter.
  ParamVec3 getVec3(std::string_view name) const;

  /// Sends failed reads to `handler` (nullptr: keep them for firstError()).
  void setFailureHandler(FailureHandler handler) { failureHandler_ = handler; }
  /// The first failed read when no handler is set, or nullopt.
  const std::optional<Error>& firstError() const { return firstError_; }

  /// One declared parameter.
  struct Entry {
    ParamType type = ParamType::String;
    std::optional<ParamValue> value;
  };
  /// Every declared parameter by name.
  const std::map<std::string, Entry, std::less<>>& entries() const { return entries_; }

 private:
  const ParamValue* find(std::string_view name, ParamType type, std::string_view readAs) const;
  void fail(std::string message) const;

  std::string owner_;
  std::map<std::string, Entry, std::less<>> entries_;
  FailureHandler failureHandler_ = nullptr;
  mutable std::optional<Error> firstError_;  ///< reads are const; the first failure is kept
};

/// The one codec of a parameter set: typed bytes, so that the reader does not parse text (the
/// daemon writes a module's set into its shared-memory slot; the module reads it back).
std::string encodeParameters(const Parameters& parameters);
/// The set `encodeParameters` wrote, or an error when the bytes are not such a set.
Result<Parameters> decodeParameters(std::string_view bytes);

}  // namespace vrflow
