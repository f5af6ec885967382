#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"

// Object types: every object of a type carries the same ordered parameter list, so an object
// chunk names parameters by index and a 64-bit mask says which ones changed.

namespace vrflow::msg {

/// The value kind of a parameter; fixes its size on the wire (docs/message-layout.md).
enum class ParamKind : std::uint8_t {
  Scalar = 1,       ///< f64
  Vec3 = 2,         ///< f64[3]
  Quat = 3,         ///< f64[4], (x, y, z, w)
  Mat3 = 4,         ///< f64[9], row-major
  Aabb = 5,         ///< f64 min[3], max[3]
  Id = 6,           ///< u64 object or resource id
  Int64 = 7,        ///< i64
  Bytes = 8,        ///< any number of bytes
  FloatArray = 9,   ///< f32[n]
  DoubleArray = 10  ///< f64[n]
};

/// Exact byte size of a fixed-size kind, or 0 for the variable-size ones.
std::size_t fixedSizeOf(ParamKind kind);
/// Element size of a kind: its fixed size, 4 or 8 for arrays, 1 for Bytes.
std::size_t elementSizeOf(ParamKind kind);
/// True when the kind's values are doubles or floats (checked for NaN and infinity).
bool holdsFloats(ParamKind kind);
/// The kind's name as written in the docs ("Vec3").
std::string_view nameOf(ParamKind kind);
/// True when `byteCount` is a valid size for a value of `kind`.
bool validSizeFor(ParamKind kind, std::uint64_t byteCount);

/// One declared parameter of an object type.
struct ParamDecl {
  std::string name;
  ParamKind kind = ParamKind::Scalar;
  bool operator==(const ParamDecl&) const = default;
};

/// A named, ordered list of parameters; its id is FNV-1a 32 of the name.
class ObjectType {
 public:
  /// Checks and builds a type: non-empty unique names, at most kMaxParams parameters.
  static Result<ObjectType> create(std::string name, std::vector<ParamDecl> params);

  /// The type's name ("rigid").
  const std::string& name() const { return name_; }
  /// The id written in object chunks.
  std::uint32_t id() const { return id_; }
  /// Parameters in index order.
  std::span<const ParamDecl> params() const { return params_; }
  /// Number of parameters.
  std::size_t paramCount() const { return params_.size(); }
  /// The parameter at `index`; index must be below paramCount().
  const ParamDecl& param(std::size_t index) const;
  /// The index of the parameter called `name`, if any.
  std::optional<std::size_t> indexOf(std::string_view name) const;

  bool operator==(const ObjectType&) const = default;

 private:
  ObjectType() = default;
  std::string name_;
  std::uint32_t id_ = 0;
  std::vector<ParamDecl> params_;
};

/// The object types a process knows. Readers check the parameter sizes of known types; objects
/// of unknown types stay readable. Thread-safe, and lookups take no lock (readers in many
/// threads never contend); types are never removed, so the pointers it hands out stay valid for
/// its lifetime.
class ObjectTypeRegistry {
 public:
  /// Most types one registry holds.
  static constexpr std::size_t kCapacity = 256;

  /// A registry holding the built-in types (builtin_types.hpp).
  ObjectTypeRegistry();
  ObjectTypeRegistry(const ObjectTypeRegistry&) = delete;
  ObjectTypeRegistry& operator=(const ObjectTypeRegistry&) = delete;
  ~ObjectTypeRegistry();

  /// The process-wide registry that MessageView::parse uses by default.
  static ObjectTypeRegistry& global();

  /// Adds a type. Adding an identical type again returns the registered one; a different type
  /// with the same name or id is an error.
  Result<const ObjectType*> add(ObjectType type);
  /// The type with this id, or nullptr.
  const ObjectType* find(std::uint32_t id) const;
  /// The type with this name, or nullptr.
  const ObjectType* find(std::string_view name) const;

 private:
  std::mutex addMutex_;
  std::array<std::unique_ptr<ObjectType>, kCapacity> types_;
  std::atomic<std::size_t> count_{0};  // types_[0, count_) are set and never change
};

}  // namespace vrflow::msg
