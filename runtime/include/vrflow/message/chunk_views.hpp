#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "vrflow/message/layout.hpp"
#include "vrflow/message/object_type.hpp"
#include "vrflow/message/packed.hpp"
#include "vrflow/message/values.hpp"

// Typed, zero-copy views of the three chunk kinds. They are made by ChunkView (reader.hpp) from
// a message that MessageView::parse checked, and never read outside the chunk's bytes.

namespace vrflow::msg {

/// One parameter entry of an object chunk.
struct ParamEntry {
  std::uint32_t index = 0;
  std::span<const std::byte> bytes;  ///< the encoded value (docs/message-layout.md)
};

/// The parameters of an object chunk, in ascending index order.
class ParamRange {
 public:
  /// Walks the entries.
  class Iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = ParamEntry;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = ParamEntry;
    Iterator() = default;
    explicit Iterator(std::span<const std::byte> rest) : rest_(rest) {}
    ParamEntry operator*() const;
    Iterator& operator++();
    bool operator==(const Iterator& other) const { return rest_.size() == other.rest_.size(); }

   private:
    std::span<const std::byte> rest_;
  };

  ParamRange() = default;
  explicit ParamRange(std::span<const std::byte> entries) : entries_(entries) {}
  Iterator begin() const { return Iterator(entries_); }
  Iterator end() const { return Iterator(std::span<const std::byte>{}); }

 private:
  std::span<const std::byte> entries_;
};

/// An object chunk: an object added, updated (changed parameters only) or deleted.
class ObjectView {
 public:
  ObjectView(std::uint64_t id, std::uint32_t typeId, ObjectOp op, std::span<const std::byte> body,
             const ObjectType* type)
      : id_(id), typeId_(typeId), op_(op), body_(body), type_(type) {}

  /// The object's id.
  std::uint64_t id() const { return id_; }
  /// The object's type id (FNV-1a 32 of the type name).
  std::uint32_t typeId() const { return typeId_; }
  /// Add, Update or Delete.
  ObjectOp op() const { return op_; }
  /// The object's type when the reader's registry knows it, else nullptr.
  const ObjectType* type() const { return type_; }
  /// Bit i set: parameter i travels in this chunk. 0 for a delete.
  std::uint64_t mask() const;
  /// True when parameter `index` travels in this chunk.
  bool has(std::size_t index) const { return index < kMaxParams && ((mask() >> index) & 1u) != 0; }
  /// Every entry, in ascending index order.
  ParamRange params() const;
  /// The encoded bytes of parameter `index`, if it travels in this chunk.
  std::optional<std::span<const std::byte>> param(std::size_t index) const;

  /// Typed reads of parameter `index`: nullopt when it is absent or its size does not fit the
  /// kind (possible only for types the reader does not know).
  std::optional<double> scalar(std::size_t index) const;
  std::optional<Vec3> vec3(std::size_t index) const;
  std::optional<Quat> quat(std::size_t index) const;
  std::optional<Mat3> mat3(std::size_t index) const;
  std::optional<Aabb> aabb(std::size_t index) const;
  std::optional<std::uint64_t> idParam(std::size_t index) const;
  std::optional<std::int64_t> int64(std::size_t index) const;
  std::optional<PackedArray<float>> floatArray(std::size_t index) const;
  std::optional<PackedArray<double>> doubleArray(std::size_t index) const;
  std::optional<std::span<const std::byte>> bytes(std::size_t index) const { return param(index); }

 private:
  template <typename T>
  std::optional<T> fixed(std::size_t index) const;

  std::uint64_t id_;
  std::uint32_t typeId_;
  ObjectOp op_;
  std::span<const std::byte> body_;
  const ObjectType* type_;
};

/// A triangle mesh resource: vertexCount xyz float triples and indexCount indices.
class MeshView {
 public:
  explicit MeshView(std::span<const std::byte> body);
  /// Vertices, indices and triangles.
  std::uint32_t vertexCount() const { return vertexCount_; }
  std::uint32_t indexCount() const { return indexCount_; }
  std::uint32_t triangleCount() const { return indexCount_ / 3; }
  /// 3 * vertexCount floats, x y z per vertex.
  PackedArray<float> xyz() const { return xyz_; }
  /// indexCount indices, each below vertexCount.
  PackedArray<std::uint32_t> indices() const { return indices_; }
  /// Vertex i (i below vertexCount).
  std::array<float, 3> vertex(std::size_t i) const;

 private:
  std::uint32_t vertexCount_ = 0;
  std::uint32_t indexCount_ = 0;
  PackedArray<float> xyz_;
  PackedArray<std::uint32_t> indices_;
};

/// A regular-grid field resource (scalar or vector), x fastest, then y, then z.
class FieldView {
 public:
  explicit FieldView(std::span<const std::byte> body);
  /// Cells along x, y, z.
  std::array<std::uint32_t, 3> dims() const { return dims_; }
  /// Floats per cell: 1 (scalar field) or 3 (vector field).
  std::uint32_t components() const { return components_; }
  /// World position of cell (0, 0, 0).
  Vec3 origin() const { return origin_; }
  /// Distance between neighbouring cells.
  double spacing() const { return spacing_; }
  /// dims[0] * dims[1] * dims[2] * components floats.
  PackedArray<float> data() const { return data_; }

 private:
  std::array<std::uint32_t, 3> dims_{};
  std::uint32_t components_ = 0;
  Vec3 origin_{};
  double spacing_ = 0.0;
  PackedArray<float> data_;
};

/// A resource chunk: large shared data referenced by id from object parameters.
class ResourceView {
 public:
  ResourceView(std::uint64_t id, ResourceKind kind, bool dynamic, std::span<const std::byte> body)
      : id_(id), kind_(kind), dynamic_(dynamic), body_(body) {}
  /// The resource's id.
  std::uint64_t id() const { return id_; }
  /// Raw, Mesh, ScalarField or VectorField.
  ResourceKind kind() const { return kind_; }
  /// True for dynamic resources (sent on change), false for static ones (sent once).
  bool dynamic() const { return dynamic_; }
  /// The body bytes, whatever the kind.
  std::span<const std::byte> raw() const { return body_; }
  /// The mesh, for a Mesh resource.
  std::optional<MeshView> mesh() const;
  /// The field, for a ScalarField or VectorField resource.
  std::optional<FieldView> field() const;

 private:
  std::uint64_t id_;
  ResourceKind kind_;
  bool dynamic_;
  std::span<const std::byte> body_;
};

/// An event chunk: an interaction event for one object.
class EventView {
 public:
  EventView(std::uint64_t id, std::uint16_t kind, std::span<const std::byte> body)
      : id_(id), kind_(kind), body_(body) {}
  /// The target object's id.
  std::uint64_t id() const { return id_; }
  /// EventKind::Force, or a user kind (>= kFirstUserEventKind).
  std::uint16_t kind() const { return kind_; }
  /// True for a force event.
  bool isForce() const { return kind_ == static_cast<std::uint16_t>(EventKind::Force); }
  /// The force, for a Force event.
  std::optional<ForceEvent> force() const;
  /// The body bytes (a user event's payload).
  std::span<const std::byte> payload() const { return body_; }

 private:
  std::uint64_t id_;
  std::uint16_t kind_;
  std::span<const std::byte> body_;
};

}  // namespace vrflow::msg
