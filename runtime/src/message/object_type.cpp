#include "vrflow/message/object_type.hpp"

#include <utility>

#include "vrflow/base/assert.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/ids.hpp"
#include "vrflow/message/layout.hpp"

namespace vrflow::msg {

std::size_t fixedSizeOf(ParamKind kind) {
  switch (kind) {
    case ParamKind::Scalar:
    case ParamKind::Id:
    case ParamKind::Int64:
      return 8;
    case ParamKind::Vec3:
      return 24;
    case ParamKind::Quat:
      return 32;
    case ParamKind::Mat3:
      return 72;
    case ParamKind::Aabb:
      return 48;
    case ParamKind::Bytes:
    case ParamKind::FloatArray:
    case ParamKind::DoubleArray:
      return 0;
  }
  return 0;
}

std::size_t elementSizeOf(ParamKind kind) {
  switch (kind) {
    case ParamKind::Bytes:
      return 1;
    case ParamKind::FloatArray:
      return 4;
    case ParamKind::DoubleArray:
      return 8;
    default:
      return fixedSizeOf(kind);
  }
}

bool holdsFloats(ParamKind kind) {
  switch (kind) {
    case ParamKind::Scalar:
    case ParamKind::Vec3:
    case ParamKind::Quat:
    case ParamKind::Mat3:
    case ParamKind::Aabb:
    case ParamKind::FloatArray:
    case ParamKind::DoubleArray:
      return true;
    default:
      return false;
  }
}

std::string_view nameOf(ParamKind kind) {
  switch (kind) {
    case ParamKind::Scalar:
      return "Scalar";
    case ParamKind::Vec3:
      return "Vec3";
    case ParamKind::Quat:
      return "Quat";
    case ParamKind::Mat3:
      return "Mat3";
    case ParamKind::Aabb:
      return "Aabb";
    case ParamKind::Id:
      return "Id";
    case ParamKind::Int64:
      return "Int64";
    case ParamKind::Bytes:
      return "Bytes";
    case ParamKind::FloatArray:
      return "FloatArray";
    case ParamKind::DoubleArray:
      return "DoubleArray";
  }
  return "unknown";
}

bool validSizeFor(ParamKind kind, std::uint64_t byteCount) {
  const std::size_t fixed = fixedSizeOf(kind);
  if (fixed != 0) return byteCount == fixed;
  return byteCount % elementSizeOf(kind) == 0;
}

Result<ObjectType> ObjectType::create(std::string name, std::vector<ParamDecl> params) {
  if (name.empty()) return makeError("an object type needs a name");
  if (params.size() > kMaxParams) {
    return makeError("object type '" + name + "' declares " + std::to_string(params.size()) +
                     " parameters; at most " + std::to_string(kMaxParams) + " are allowed");
  }
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].name.empty()) {
      return makeError("object type '" + name + "': parameter " + std::to_string(i) +
                       " has no name");
    }
    if (fixedSizeOf(params[i].kind) == 0 && elementSizeOf(params[i].kind) == 0) {
      return makeError("object type '" + name + "': parameter '" + params[i].name +
                       "' has an unknown kind");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (params[j].name == params[i].name) {
        return makeError("object type '" + name + "' declares parameter '" + params[i].name +
                         "' twice");
      }
    }
  }
  ObjectType type;
  type.id_ = fnv1a32(name);
  type.name_ = std::move(name);
  type.params_ = std::move(params);
  return type;
}

const ParamDecl& ObjectType::param(std::size_t index) const {
  VRFLOW_ASSERT(index < params_.size(), "parameter index beyond the type's parameter count");
  return params_[index];
}

std::optional<std::size_t> ObjectType::indexOf(std::string_view name) const {
  for (std::size_t i = 0; i < params_.size(); ++i) {
    if (params_[i].name == name) return i;
  }
  return std::nullopt;
}

ObjectTypeRegistry::ObjectTypeRegistry() {
  for (const ObjectType* type : builtinTypes()) {
    const auto added = add(*type);
    VRFLOW_ASSERT(added.ok(), "built-in object types collide");
  }
}

ObjectTypeRegistry::~ObjectTypeRegistry() = default;

ObjectTypeRegistry& ObjectTypeRegistry::global() {
  static ObjectTypeRegistry registry;
  return registry;
}

Result<const ObjectType*> ObjectTypeRegistry::add(ObjectType type) {
  std::lock_guard lock(addMutex_);
  const std::size_t count = count_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < count; ++i) {
    const ObjectType& known = *types_[i];
    if (known.id() != type.id() && known.name() != type.name()) continue;
    if (known == type) return &known;
    if (known.name() != type.name()) {
      return makeError("object type '" + type.name() + "' has the same id as '" + known.name() +
                       "'; rename one of them");
    }
    return makeError("object type '" + type.name() +
                     "' is already registered with a different parameter list");
  }
  if (count == kCapacity) {
    return makeError("cannot register object type '" + type.name() + "': the registry holds " +
                     std::to_string(kCapacity) + " types already");
  }
  types_[count] = std::make_unique<ObjectType>(std::move(type));
  const ObjectType* added = types_[count].get();
  count_.store(count + 1, std::memory_order_release);  // publishes types_[count]
  return added;
}

const ObjectType* ObjectTypeRegistry::find(std::uint32_t id) const {
  const std::size_t count = count_.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < count; ++i) {
    if (types_[i]->id() == id) return types_[i].get();
  }
  return nullptr;
}

const ObjectType* ObjectTypeRegistry::find(std::string_view name) const {
  const std::size_t count = count_.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < count; ++i) {
    if (types_[i]->name() == name) return types_[i].get();
  }
  return nullptr;
}

}  // namespace vrflow::msg
