#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrflow/message/reader.hpp"
#include "vrflow/message/values.hpp"

// The viewer's picture of the world, built from the messages it receives: every object by id
// with its latest parameters (adds carry all of them, updates only the changed ones, deletes
// remove the object), shapes decoded once into render meshes, the latest particle resources.

namespace vrflow::viewer {

/// A triangle mesh ready to draw: three floats per vertex and per normal, three indices per
/// triangle. Shape meshes are split at sharp edges so that a box has flat faces and a sphere
/// smooth ones.
struct DrawMesh {
  std::vector<float> xyz;
  std::vector<float> normals;
  std::vector<std::uint32_t> indices;
};

/// What kind of drawing an object gets.
enum class ObjectKind { Rigid, MassSpring, Fluid, Point, User };

/// One object as last seen.
struct CachedObject {
  std::uint64_t id = 0;
  ObjectKind kind = ObjectKind::Rigid;
  msg::Vec3 position{};                ///< rigid, point
  msg::Quat orientation{0, 0, 0, 1};   ///< rigid
  std::uint64_t shapeId = 0;           ///< rigid: the shape resource (0: none yet)
  std::vector<double> positions;       ///< massspring: xyz per mass
  std::vector<std::uint32_t> surface;  ///< massspring: three mass indices per triangle
  std::uint64_t particlesId = 0;       ///< fluid: the particle resource
  std::uint64_t surfaceId = 0;  ///< fluid: the surface mesh (0: none, particles); user: its mesh
  std::optional<msg::Aabb> bounds;  ///< the sender's `bounds` (a point: its position)
};

/// Counters a viewer reports (and tests check).
struct SceneStats {
  std::uint64_t messages = 0;
  std::uint64_t objectChunks = 0;
  std::uint64_t resourceChunks = 0;
  std::uint64_t rejectedShapes = 0;  ///< shape resources that failed to decode
  std::uint64_t ignoredChunks = 0;   ///< objects of types the viewer does not draw, events
};

/// Objects, shapes and particles, updated one message at a time. Not thread-safe.
class SceneCache {
 public:
  /// Receives one line per problem (a forged shape, an update for an unknown object); by default
  /// the lines go to stderr with the "vrflow-viewer: " prefix.
  using LogFn = std::function<void(const std::string&)>;

  /// An empty scene; `segments` sets how finely spheres and capsules are tessellated.
  explicit SceneCache(int segments = 24, LogFn log = {});

  /// Applies every chunk of one message in order. Problems are logged, never fatal.
  void apply(const msg::MessageView& message);

  /// Every object, by id (ascending, so drawing order is deterministic).
  const std::map<std::uint64_t, CachedObject>& objects() const { return objects_; }
  /// The object with this id, or nullptr.
  const CachedObject* find(std::uint64_t id) const;
  /// The render mesh of shape resource `id` in its body frame, or nullptr when it has not
  /// arrived or was rejected. Each shape is decoded once.
  const DrawMesh* shapeMesh(std::uint64_t id) const;
  /// The latest particle positions (xyz floats) of resource `id`, or nullptr.
  const std::vector<float>* particles(std::uint64_t id) const;
  /// The triangles (three vertex indices each) of Mesh resource `id`, whose vertices
  /// particles(id) holds, or nullptr when it has none (a fluid's surface has them).
  const std::vector<std::uint32_t>* meshIndices(std::uint64_t id) const;
  /// Raw and particle resources held. After each message those no object names are dropped, so
  /// a sender that makes a new resource id every iteration does not grow the cache.
  std::size_t heldResources() const { return otherRaw_.size() + particles_.size(); }
  /// Counters so far.
  const SceneStats& stats() const { return stats_; }

 private:
  void applyObject(const msg::ObjectView& object);
  void applyResource(const msg::ResourceView& resource);
  void resolveShapes();
  void dropUnreferenced();
  void log(const std::string& line);

  int segments_;
  LogFn log_;
  std::map<std::uint64_t, CachedObject> objects_;
  // Sizes of the Raw resources without the shape magic, to reject one a rigid object names.
  std::map<std::uint64_t, std::size_t> otherRaw_;
  std::map<std::uint64_t, std::shared_ptr<const DrawMesh>> shapes_;  // nullptr: rejected
  std::map<std::uint64_t, std::vector<float>> particles_;
  std::map<std::uint64_t, std::vector<std::uint32_t>> meshIndices_;
  SceneStats stats_;
};

/// Turns a shape's render mesh into a DrawMesh with normals: each triangle corner averages the
/// normals of the triangles around its vertex that bend less than `creaseDegrees` from its own.
DrawMesh buildDrawMesh(const std::vector<float>& xyz, const std::vector<std::uint32_t>& indices,
                       double creaseDegrees = 40.0);

}  // namespace vrflow::viewer
