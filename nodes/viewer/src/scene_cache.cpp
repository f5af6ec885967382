#include "vrflow/viewer/scene_cache.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <unordered_map>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/shape.hpp"

namespace vrflow::viewer {
namespace {

constexpr std::uint32_t kShapeMagic = 0x31504853;  // "SHP1", docs/message-layout.md

bool hasShapeMagic(std::span<const std::byte> bytes) {
  if (bytes.size() < 4) return false;
  std::uint32_t magic = 0;
  std::memcpy(&magic, bytes.data(), 4);
  return magic == kShapeMagic;
}

std::optional<ObjectKind> kindOf(std::uint32_t typeId) {
  if (typeId == msg::rigidType().id()) return ObjectKind::Rigid;
  if (typeId == msg::massSpringType().id()) return ObjectKind::MassSpring;
  if (typeId == msg::fluidType().id()) return ObjectKind::Fluid;
  if (typeId == msg::pointType().id()) return ObjectKind::Point;
  if (typeId == msg::userType().id()) return ObjectKind::User;
  return std::nullopt;
}

std::array<double, 3> faceNormal(const std::vector<float>& xyz, std::uint32_t a, std::uint32_t b,
                                 std::uint32_t c) {
  const auto p = [&](std::uint32_t i, int k) { return static_cast<double>(xyz[3 * i + k]); };
  const double ux = p(b, 0) - p(a, 0), uy = p(b, 1) - p(a, 1), uz = p(b, 2) - p(a, 2);
  const double vx = p(c, 0) - p(a, 0), vy = p(c, 1) - p(a, 1), vz = p(c, 2) - p(a, 2);
  return {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};  // length: twice the area
}

std::array<double, 3> normalised(const std::array<double, 3>& v) {
  const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (length <= 0.0) return {0.0, 1.0, 0.0};
  return {v[0] / length, v[1] / length, v[2] / length};
}

}  // namespace

DrawMesh buildDrawMesh(const std::vector<float>& xyz, const std::vector<std::uint32_t>& indices,
                       double creaseDegrees) {
  const std::size_t triangles = indices.size() / 3;
  std::vector<std::array<double, 3>> faceNormals(triangles);
  std::vector<std::array<double, 3>> unitNormals(triangles);
  // Triangles around each vertex.
  std::vector<std::vector<std::uint32_t>> around(xyz.size() / 3);
  for (std::size_t t = 0; t < triangles; ++t) {
    faceNormals[t] = faceNormal(xyz, indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]);
    unitNormals[t] = normalised(faceNormals[t]);
    for (int k = 0; k < 3; ++k) around[indices[3 * t + k]].push_back(static_cast<std::uint32_t>(t));
  }
  const double cosCrease = std::cos(creaseDegrees * 3.14159265358979323846 / 180.0);
  DrawMesh mesh;
  mesh.xyz.reserve(indices.size() * 3);
  mesh.normals.reserve(indices.size() * 3);
  mesh.indices.reserve(indices.size());
  // One drawn vertex per distinct (vertex, normal) pair, so smooth parts share vertices.
  std::unordered_map<std::uint64_t, std::uint32_t> emitted;
  for (std::size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = indices[3 * t + k];
      std::array<double, 3> sum{0, 0, 0};
      std::uint32_t smallest = static_cast<std::uint32_t>(t);
      for (const std::uint32_t other : around[v]) {
        const auto& n = unitNormals[other];
        const auto& own = unitNormals[t];
        if (n[0] * own[0] + n[1] * own[1] + n[2] * own[2] < cosCrease) continue;
        for (int c = 0; c < 3; ++c) sum[c] += faceNormals[other][c];
        smallest = std::min(smallest, other);
      }
      // The set of faces joined is identified by its smallest member (same set, same normal).
      const std::uint64_t key = (static_cast<std::uint64_t>(v) << 32) | smallest;
      auto [it, inserted] =
          emitted.try_emplace(key, static_cast<std::uint32_t>(mesh.xyz.size() / 3));
      if (inserted) {
        const auto n = normalised(sum);
        for (int c = 0; c < 3; ++c) {
          mesh.xyz.push_back(xyz[3 * v + c]);
          mesh.normals.push_back(static_cast<float>(n[c]));
        }
      }
      mesh.indices.push_back(it->second);
    }
  }
  return mesh;
}

SceneCache::SceneCache(int segments, LogFn log) : segments_(segments), log_(std::move(log)) {}

void SceneCache::log(const std::string& line) {
  if (log_) {
    log_(line);
  } else {
    std::fprintf(stderr, "vrflow-viewer: %s\n", line.c_str());
  }
}

const CachedObject* SceneCache::find(std::uint64_t id) const {
  const auto it = objects_.find(id);
  return it == objects_.end() ? nullptr : &it->second;
}

const DrawMesh* SceneCache::shapeMesh(std::uint64_t id) const {
  const auto it = shapes_.find(id);
  return it == shapes_.end() ? nullptr : it->second.get();
}

const std::vector<float>* SceneCache::particles(std::uint64_t id) const {
  const auto it = particles_.find(id);
  return it == particles_.end() ? nullptr : &it->second;
}

const std::vector<std::uint32_t>* SceneCache::meshIndices(std::uint64_t id) const {
  const auto it = meshIndices_.find(id);
  return it == meshIndices_.end() ? nullptr : &it->second;
}

void SceneCache::apply(const msg::MessageView& message) {
  ++stats_.messages;
  for (const auto chunk : message) {
    if (const auto object = chunk.asObject()) {
      ++stats_.objectChunks;
      applyObject(*object);
    } else if (const auto resource = chunk.asResource()) {
      ++stats_.resourceChunks;
      applyResource(*resource);
    } else {
      ++stats_.ignoredChunks;
    }
  }
  resolveShapes();
  dropUnreferenced();
}

void SceneCache::applyObject(const msg::ObjectView& object) {
  const auto kind = kindOf(object.typeId());
  if (!kind) {
    ++stats_.ignoredChunks;
    return;
  }
  if (object.op() == msg::ObjectOp::Delete) {
    objects_.erase(object.id());
    return;
  }
  auto it = objects_.find(object.id());
  if (it == objects_.end()) {
    if (object.op() == msg::ObjectOp::Update) {
      // An update for an object never added (the viewer joined late, or a filter dropped the
      // add): keep what it carries, the missing parameters keep their defaults.
      log("update for unknown object " + std::to_string(object.id()) + "; treating it as an add");
    }
    it = objects_.emplace(object.id(), CachedObject{}).first;
    it->second.id = object.id();
    it->second.kind = *kind;
  } else if (it->second.kind != *kind) {
    log("object " + std::to_string(object.id()) + " changed type; replacing it");
    it->second = CachedObject{};
    it->second.id = object.id();
    it->second.kind = *kind;
  } else if (object.op() == msg::ObjectOp::Add) {
    // An add carries the whole object: nothing of an earlier incarnation survives.
    it->second = CachedObject{};
    it->second.id = object.id();
    it->second.kind = *kind;
  }
  CachedObject& cached = it->second;
  switch (*kind) {
    case ObjectKind::Rigid:
      if (auto p = object.vec3(msg::RigidParam::kPosition)) cached.position = *p;
      if (auto q = object.quat(msg::RigidParam::kOrientation)) cached.orientation = *q;
      if (auto s = object.idParam(msg::RigidParam::kShape)) cached.shapeId = *s;
      if (auto b = object.aabb(msg::RigidParam::kBounds)) cached.bounds = *b;
      break;
    case ObjectKind::Point:
      if (auto p = object.vec3(msg::PointParam::kPosition)) {
        cached.position = *p;
        cached.bounds = msg::Aabb{*p, *p};
      }
      break;
    case ObjectKind::MassSpring:
      if (auto p = object.doubleArray(msg::MassSpringParam::kPositions)) {
        cached.positions.resize(p->size());
        p->copyTo(cached.positions);
      }
      if (auto s = object.bytes(msg::MassSpringParam::kSurface)) {
        const msg::PackedArray<std::uint32_t> indices(*s);
        cached.surface.resize(indices.size() - indices.size() % 3);
        for (std::size_t i = 0; i < cached.surface.size(); ++i) cached.surface[i] = indices[i];
      }
      if (auto b = object.aabb(msg::MassSpringParam::kBounds)) cached.bounds = *b;
      break;
    case ObjectKind::Fluid:
      if (auto r = object.idParam(msg::FluidParam::kParticles)) cached.particlesId = *r;
      if (auto r = object.idParam(msg::FluidParam::kSurface)) cached.surfaceId = *r;
      if (auto b = object.aabb(msg::FluidParam::kBounds)) cached.bounds = *b;
      break;
    case ObjectKind::User:
      if (auto r = object.idParam(msg::UserParam::kMesh)) cached.surfaceId = *r;
      if (auto p = object.vec3(msg::UserParam::kPosition)) cached.position = *p;
      if (auto b = object.aabb(msg::UserParam::kBounds)) cached.bounds = *b;
      break;
  }
}

void SceneCache::applyResource(const msg::ResourceView& resource) {
  const auto id = resource.id();
  if (resource.kind() == msg::ResourceKind::Mesh) {
    if (const auto mesh = resource.mesh()) {
      auto& xyz = particles_[id];
      xyz.resize(mesh->xyz().size());
      mesh->xyz().copyTo(xyz);
      if (mesh->indexCount() > 0) {
        auto& indices = meshIndices_[id];
        indices.resize(mesh->indexCount());
        mesh->indices().copyTo(indices);
      } else {
        meshIndices_.erase(id);
      }
    }
    return;
  }
  if (resource.kind() != msg::ResourceKind::Raw) {
    ++stats_.ignoredChunks;
    return;
  }
  const auto raw = resource.raw();
  if (hasShapeMagic(raw)) {
    if (shapes_.contains(id) && !resource.dynamic()) return;  // a static shape is decoded once
    otherRaw_.erase(id);
    auto shape = msg::decodeShape(raw);
    if (!shape) {
      ++stats_.rejectedShapes;
      log("shape resource " + std::to_string(id) + " rejected: " + shape.error().message +
          "; objects using it are not drawn");
      shapes_[id] = nullptr;
      return;
    }
    const auto render = msg::renderMesh(*shape, segments_);
    shapes_[id] = std::make_shared<const DrawMesh>(buildDrawMesh(render.xyz, render.indices));
    return;
  }
  // Not a shape: a raw array of xyz floats (fluid particles), or something a rigid object may
  // still name as its shape (then rejected in resolveShapes).
  otherRaw_[id] = raw.size();
  if (raw.size() % 12 == 0) {
    auto& xyz = particles_[id];
    xyz.resize(raw.size() / 4);
    if (!raw.empty()) std::memcpy(xyz.data(), raw.data(), raw.size());
    for (float& v : xyz) {
      if (!std::isfinite(v)) v = 0.0f;  // a non-finite particle is drawn at the origin
    }
  }
}

void SceneCache::resolveShapes() {
  for (const auto& [id, object] : objects_) {
    if (object.kind != ObjectKind::Rigid || object.shapeId == 0) continue;
    if (shapes_.contains(object.shapeId)) continue;
    const auto raw = otherRaw_.find(object.shapeId);
    if (raw == otherRaw_.end()) continue;  // not arrived yet
    ++stats_.rejectedShapes;
    log("shape resource " + std::to_string(object.shapeId) + " of rigid object " +
        std::to_string(id) + " rejected: no shape magic 'SHP1' (" + std::to_string(raw->second) +
        " bytes); objects using it are not drawn");
    shapes_[object.shapeId] = nullptr;
  }
}

void SceneCache::dropUnreferenced() {
  if (otherRaw_.empty() && particles_.empty()) return;
  std::set<std::uint64_t> named;
  for (const auto& [id, object] : objects_) {
    if (object.kind == ObjectKind::Fluid) named.insert({object.particlesId, object.surfaceId});
    if (object.kind == ObjectKind::User) named.insert(object.surfaceId);
  }
  std::erase_if(meshIndices_, [&](const auto& entry) { return !named.contains(entry.first); });
  std::erase_if(otherRaw_, [&](const auto& entry) { return !named.contains(entry.first); });
  std::erase_if(particles_, [&](const auto& entry) { return !named.contains(entry.first); });
}

}  // namespace vrflow::viewer
