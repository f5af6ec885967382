#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/rigid/body.hpp"

// Scenes: a JSON file of bodies (format in nodes/rigid/README.md) and generators for tests and
// benchmarks. Bodies get ids 1, 2, ... in file/generation order.

namespace vrflow::rigid {

/// Reads a scene file; errors name the file (and the line for syntax and per-body errors).
Result<std::vector<Body>> loadScene(const std::string& path);
/// Parses scene text; `origin` names it in errors.
Result<std::vector<Body>> parseScene(std::string_view text, const std::string& origin);

/// A generated scene. `spec` is `KIND:N`:
///  - `boxes:N`  N unit-density 0.4 m boxes in a jittered grid above a static ground (bench);
///  - `mixed:N`  N spheres, boxes, capsules and convex hulls dropped into a 2 m x 2 m box
///               (static ground and four walls): the demo scene's rigid objects;
///  - `stack:N`  N 0.5 m boxes stacked on the ground;
///  - `bowls:N`  N bowls (moving concave triangle meshes, bowlMesh(0.3, 0.3, 0.05), density
///               500) in a row on the ground, a sphere and a box dropped into each (bench).
/// Static bodies (ground, walls) come first.
Result<std::vector<Body>> generateScene(std::string_view spec);

/// A convex hull shape from points: Bullet's hull computer gives the faces (triangulated,
/// outward); the points are recentred so that the hull's centroid is the origin, and the shift
/// is returned in `centroid` when given.
Result<msg::Shape> convexHullFromPoints(const std::vector<Vec3>& points, Vec3* centroid = nullptr);

}  // namespace vrflow::rigid
