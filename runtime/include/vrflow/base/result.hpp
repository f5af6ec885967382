#pragma once

#include <string>
#include <utility>
#include <variant>

namespace vrflow {

/// A user's or the world's mistake, with a message a person can act on.
struct Error {
  std::string message;
};

/// An expected-like value: either a T or an Error. Errors never cross a library boundary as
/// exceptions; they travel in this type.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::move(value)) {}  // NOLINT(google-explicit-constructor): by design
  Result(Error error)
      : state_(std::move(error)) {}  // NOLINT(google-explicit-constructor): by design

  /// True when a value is held.
  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(state_); }
  const T& value() const& { return std::get<0>(state_); }
  T&& value() && { return std::get<0>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  /// The error; only valid when !ok().
  const Error& error() const { return std::get<1>(state_); }

 private:
  std::variant<T, Error> state_;
};

/// Result of an operation that returns nothing but may fail.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)), failed_(true) {}  // NOLINT: by design
  bool ok() const { return !failed_; }
  explicit operator bool() const { return ok(); }
  const Error& error() const { return error_; }

 private:
  Error error_;
  bool failed_ = false;
};

/// Shorthand to build an Error.
inline Error makeError(std::string message) {
  return Error{std::move(message)};
}

}  // namespace vrflow
