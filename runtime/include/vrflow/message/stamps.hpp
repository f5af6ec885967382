#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "vrflow/message/layout.hpp"

// Stamps: what every message says about itself besides its chunks.

namespace vrflow::msg {

/// A named user stamp with an owned value (for building messages).
struct UserStamp {
  std::string name;
  std::variant<std::int64_t, double, std::string> value;
  bool operator==(const UserStamp&) const = default;
};

/// Every stamp of a message, owned (for building messages and keeping stamps past a view).
struct Stamps {
  std::string source;            ///< id of the sending module
  std::uint64_t iteration = 0;   ///< the sender's iteration number
  double simTime = 0.0;          ///< simulation time of the data, seconds
  double timeStep = 0.0;         ///< simulation time step, seconds
  std::uint64_t sendTimeNs = 0;  ///< wall clock at send, ns since the epoch (not in digests)
  std::vector<UserStamp> user;   ///< user stamps, in order
  bool operator==(const Stamps&) const = default;
};

/// One user stamp inside a checked message.
class UserStampView {
 public:
  UserStampView(std::string_view name, StampType type, std::span<const std::byte> value)
      : name_(name), type_(type), value_(value) {}
  /// The stamp's name and value type.
  std::string_view name() const { return name_; }
  StampType type() const { return type_; }
  /// The value when it has that type.
  std::optional<std::int64_t> asInt64() const;
  std::optional<double> asDouble() const;
  std::optional<std::string_view> asString() const;
  /// An owned copy.
  UserStamp toUserStamp() const;

 private:
  std::string_view name_;
  StampType type_;
  std::span<const std::byte> value_;
};

/// The user stamps of a checked message, iterable in order.
class UserStampRange {
 public:
  /// Walks the packed user stamps.
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = UserStampView;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = UserStampView;
    Iterator() = default;
    Iterator(std::span<const std::byte> rest, std::uint32_t left) : rest_(rest), left_(left) {}
    UserStampView operator*() const;
    Iterator& operator++();
    bool operator==(const Iterator& other) const { return left_ == other.left_; }

   private:
    std::span<const std::byte> rest_;
    std::uint32_t left_ = 0;
  };

  UserStampRange() = default;
  UserStampRange(std::span<const std::byte> packed, std::uint32_t count)
      : packed_(packed), count_(count) {}
  /// Number of user stamps.
  std::uint32_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  Iterator begin() const { return Iterator(packed_, count_); }
  Iterator end() const { return Iterator(std::span<const std::byte>{}, 0); }
  /// The first user stamp called `name`.
  std::optional<UserStampView> find(std::string_view name) const;

 private:
  std::span<const std::byte> packed_;
  std::uint32_t count_ = 0;
};

/// The stamps of a checked message; `source` and the user stamps point into the message.
struct StampsView {
  std::string_view source;
  std::uint64_t iteration = 0;
  double simTime = 0.0;
  double timeStep = 0.0;
  std::uint64_t sendTimeNs = 0;
  UserStampRange user;

  /// An owned copy (to stamp a new message with the same values, or to keep them).
  Stamps toStamps() const;
};

}  // namespace vrflow::msg
