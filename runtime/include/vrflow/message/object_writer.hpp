#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>

#include "vrflow/message/object_type.hpp"
#include "vrflow/message/values.hpp"

namespace vrflow::msg {

class MessageBuilder;

/// Writes the parameters of one object chunk (from MessageBuilder::addObject). Only the
/// parameters set travel; each set() marks its bit in the chunk's mask. Parameters may be set in
/// any order (they are stored by index) and setting one twice keeps the last value.
/// Valid until the next chunk is added to the builder; using it after that is a bug.
/// Each setter takes an index (or a name of the object's type) and a value whose C++ type must
/// match the parameter's kind: double Scalar, Vec3, Quat, Mat3, Aabb, uint64_t Id, int64_t Int64,
/// span<const float> FloatArray, span<const double> DoubleArray, span<const std::byte> Bytes.
class ObjectWriter {
 public:
  ObjectWriter& set(std::size_t index, double value);
  ObjectWriter& set(std::size_t index, const Vec3& value);
  ObjectWriter& set(std::size_t index, const Quat& value);
  ObjectWriter& set(std::size_t index, const Mat3& value);
  ObjectWriter& set(std::size_t index, const Aabb& value);
  ObjectWriter& set(std::size_t index, std::uint64_t id);
  ObjectWriter& set(std::size_t index, std::int64_t value);
  ObjectWriter& set(std::size_t index, std::span<const float> values);
  ObjectWriter& set(std::size_t index, std::span<const double> values);
  ObjectWriter& set(std::size_t index, std::span<const std::byte> bytes);

  /// Sets the parameter called `name` (it must exist in the object's type).
  template <typename Name, typename T>
  requires std::is_convertible_v<const Name&, std::string_view> ObjectWriter& set(const Name& name,
                                                                                  const T& value) {
    return set(indexOf(std::string_view(name)), value);
  }

  /// Sets a parameter from its encoded bytes (forwarding); the size must suit its kind.
  ObjectWriter& setEncoded(std::size_t index, std::span<const std::byte> bytes);

  /// The type this object was declared with.
  const ObjectType& type() const { return *type_; }

 private:
  friend class MessageBuilder;
  ObjectWriter(MessageBuilder* builder, const ObjectType* type, std::uint64_t token)
      : builder_(builder), type_(type), token_(token) {}
  std::size_t indexOf(std::string_view name) const;
  ObjectWriter& write(std::size_t index, ParamKind kind, const void* data, std::size_t size);

  MessageBuilder* builder_;
  const ObjectType* type_;
  std::uint64_t token_;
};

}  // namespace vrflow::msg
