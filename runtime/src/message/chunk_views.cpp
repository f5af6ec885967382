#include "vrflow/message/chunk_views.hpp"

namespace vrflow::msg {

ParamEntry ParamRange::Iterator::operator*() const {
  const auto length = loadAt<std::uint32_t>(rest_, 4);
  return ParamEntry{loadAt<std::uint32_t>(rest_, 0),
                    sliceAt(rest_, BodyLayout::kParamEntryHeader, length)};
}

ParamRange::Iterator& ParamRange::Iterator::operator++() {
  const std::uint64_t size =
      BodyLayout::kParamEntryHeader + padTo8(loadAt<std::uint32_t>(rest_, 4));
  rest_ = size <= rest_.size() ? rest_.subspan(static_cast<std::size_t>(size))
                               : std::span<const std::byte>{};
  return *this;
}

std::uint64_t ObjectView::mask() const {
  return loadAt<std::uint64_t>(body_, 0);
}

ParamRange ObjectView::params() const {
  if (body_.size() < BodyLayout::kObjectMask) return ParamRange();
  return ParamRange(body_.subspan(BodyLayout::kObjectMask));
}

std::optional<std::span<const std::byte>> ObjectView::param(std::size_t index) const {
  if (!has(index)) return std::nullopt;
  for (const ParamEntry entry : params()) {
    if (entry.index == index) return entry.bytes;
    if (entry.index > index) break;
  }
  return std::nullopt;
}

template <typename T>
std::optional<T> ObjectView::fixed(std::size_t index) const {
  const auto bytes = param(index);
  if (!bytes || bytes->size() != sizeof(T)) return std::nullopt;
  return loadRaw<T>(bytes->data());
}

std::optional<double> ObjectView::scalar(std::size_t index) const {
  return fixed<double>(index);
}
std::optional<Vec3> ObjectView::vec3(std::size_t index) const {
  return fixed<Vec3>(index);
}
std::optional<Quat> ObjectView::quat(std::size_t index) const {
  return fixed<Quat>(index);
}
std::optional<Mat3> ObjectView::mat3(std::size_t index) const {
  return fixed<Mat3>(index);
}
std::optional<std::uint64_t> ObjectView::idParam(std::size_t index) const {
  return fixed<std::uint64_t>(index);
}
std::optional<std::int64_t> ObjectView::int64(std::size_t index) const {
  return fixed<std::int64_t>(index);
}

std::optional<Aabb> ObjectView::aabb(std::size_t index) const {
  const auto packed = fixed<std::array<double, 6>>(index);
  if (!packed) return std::nullopt;
  const auto& v = *packed;
  return Aabb{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
}

std::optional<PackedArray<float>> ObjectView::floatArray(std::size_t index) const {
  const auto bytes = param(index);
  if (!bytes || bytes->size() % sizeof(float) != 0) return std::nullopt;
  return PackedArray<float>(*bytes);
}

std::optional<PackedArray<double>> ObjectView::doubleArray(std::size_t index) const {
  const auto bytes = param(index);
  if (!bytes || bytes->size() % sizeof(double) != 0) return std::nullopt;
  return PackedArray<double>(*bytes);
}

MeshView::MeshView(std::span<const std::byte> body)
    : vertexCount_(loadAt<std::uint32_t>(body, 0)), indexCount_(loadAt<std::uint32_t>(body, 4)) {
  const std::uint64_t xyzBytes = std::uint64_t{vertexCount_} * 12u;
  xyz_ = PackedArray<float>(sliceAt(body, BodyLayout::kMeshHeader, xyzBytes));
  indices_ = PackedArray<std::uint32_t>(
      sliceAt(body, BodyLayout::kMeshHeader + xyzBytes, std::uint64_t{indexCount_} * 4u));
  // Bytes that do not hold what the counts say (never after parse) read as an empty mesh.
  if (xyz_.size() != std::uint64_t{vertexCount_} * 3u || indices_.size() != indexCount_) {
    vertexCount_ = 0;
    indexCount_ = 0;
    xyz_ = {};
    indices_ = {};
  }
}

std::array<float, 3> MeshView::vertex(std::size_t i) const {
  return {xyz_[3 * i], xyz_[3 * i + 1], xyz_[3 * i + 2]};
}

FieldView::FieldView(std::span<const std::byte> body)
    : dims_{loadAt<std::uint32_t>(body, 0), loadAt<std::uint32_t>(body, 4),
            loadAt<std::uint32_t>(body, 8)},
      components_(loadAt<std::uint32_t>(body, 12)),
      origin_(loadAt<Vec3>(body, 16)),
      spacing_(loadAt<double>(body, 40)),
      data_(body.size() >= BodyLayout::kFieldHeader ? body.subspan(BodyLayout::kFieldHeader)
                                                    : std::span<const std::byte>{}) {}

std::optional<MeshView> ResourceView::mesh() const {
  if (kind_ != ResourceKind::Mesh) return std::nullopt;
  return MeshView(body_);
}

std::optional<FieldView> ResourceView::field() const {
  if (kind_ != ResourceKind::ScalarField && kind_ != ResourceKind::VectorField) return std::nullopt;
  return FieldView(body_);
}

std::optional<ForceEvent> EventView::force() const {
  if (!isForce() || body_.size() != BodyLayout::kForce) return std::nullopt;
  ForceEvent event;
  event.force = loadRaw<Vec3>(body_.data());
  event.torque = loadRaw<Vec3>(body_.data() + 24);
  event.point = loadRaw<Vec3>(body_.data() + 48);
  event.duration = loadRaw<double>(body_.data() + 72);
  return event;
}

}  // namespace vrflow::msg
