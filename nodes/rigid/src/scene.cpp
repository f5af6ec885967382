#include "vrflow/rigid/scene.hpp"

#include <LinearMath/btConvexHullComputer.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "vrflow/base/file_access.hpp"
#include "vrflow/rigid/mesh.hpp"

namespace vrflow::rigid {
namespace {

using nlohmann::json;

std::size_t lineOf(std::string_view text, std::size_t byte) {
  byte = std::min(byte, text.size());
  return 1 + static_cast<std::size_t>(
                 std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(byte), '\n'));
}

// Errors inside one body: thrown as std::runtime_error, caught per body and decorated.
struct BodyError {
  std::string message;
};

double number(const json& j, const char* key) {
  if (!j.is_number()) throw BodyError{std::string("'") + key + "' must be a number"};
  const double x = j.get<double>();
  if (!std::isfinite(x)) throw BodyError{std::string("'") + key + "' must be finite"};
  return x;
}

template <std::size_t N>
std::array<double, N> vector(const json& j, const char* key) {
  if (!j.is_array() || j.size() != N)
    throw BodyError{std::string("'") + key + "' must be an array of " + std::to_string(N) +
                    " numbers"};
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = number(j[i], key);
  return out;
}

std::vector<Vec3> points(const json& j, const char* key) {
  if (!j.is_array() || j.empty())
    throw BodyError{std::string("'") + key + "' must be a non-empty array of [x, y, z]"};
  std::vector<Vec3> out;
  for (const auto& p : j) out.push_back(vector<3>(p, key));
  return out;
}

void onlyKeys(const json& j, std::initializer_list<const char*> keys, const std::string& where) {
  for (auto it = j.begin(); it != j.end(); ++it)
    if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return it.key() == k; }))
      throw BodyError{where + "unknown key '" + it.key() + "'"};
}

// The shape in its body frame; `offset` receives the shift applied to centre hulls and meshes.
msg::Shape parseShape(const json& j, Vec3& offset) {
  offset = {};
  if (!j.is_object() || !j.contains("type") || !j["type"].is_string())
    throw BodyError{
        "'shape' must be an object with a 'type' (sphere, box, capsule, convexHull, triangleMesh)"};
  const std::string type = j["type"].get<std::string>();
  msg::Shape shape;
  if (type == "sphere") {
    onlyKeys(j, {"type", "radius"}, "shape: ");
    shape = msg::Shape::sphere(number(j.value("radius", json()), "radius"));
  } else if (type == "box") {
    onlyKeys(j, {"type", "halfExtents"}, "shape: ");
    shape = msg::Shape::box(vector<3>(j.value("halfExtents", json()), "halfExtents"));
  } else if (type == "capsule") {
    onlyKeys(j, {"type", "radius", "halfHeight"}, "shape: ");
    shape = msg::Shape::capsule(number(j.value("radius", json()), "radius"),
                                number(j.value("halfHeight", json()), "halfHeight"));
  } else if (type == "convexHull") {
    onlyKeys(j, {"type", "points"}, "shape: ");
    auto hull = convexHullFromPoints(points(j.value("points", json()), "points"), &offset);
    if (!hull) throw BodyError{hull.error().message};
    shape = std::move(hull.value());
  } else if (type == "triangleMesh") {
    onlyKeys(j, {"type", "vertices", "triangles"}, "shape: ");
    const auto vertices = points(j.value("vertices", json()), "vertices");
    std::vector<double> xyz;
    for (const auto& v : vertices) xyz.insert(xyz.end(), v.begin(), v.end());
    std::vector<std::uint32_t> indices;
    const json& t = j.value("triangles", json());
    if (!t.is_array() || t.empty())
      throw BodyError{"'triangles' must be a non-empty array of [i, j, k]"};
    for (const auto& tri : t) {
      if (!tri.is_array() || tri.size() != 3)
        throw BodyError{"'triangles' must hold [i, j, k] vertex indices"};
      for (const auto& i : tri) {
        if (!i.is_number_unsigned() || i.get<std::uint64_t>() >= vertices.size())
          throw BodyError{"'triangles' index out of range (0.." +
                          std::to_string(vertices.size() - 1) + ")"};
        indices.push_back(static_cast<std::uint32_t>(i.get<std::uint64_t>()));
      }
    }
    shape = msg::Shape::triangleMesh(std::move(xyz), std::move(indices));
  } else {
    throw BodyError{"unknown shape type '" + type +
                    "' (sphere, box, capsule, convexHull, triangleMesh)"};
  }
  if (auto status = msg::validateShape(shape); !status)
    throw BodyError{"shape: " + status.error().message};
  return shape;
}

Body parseBody(const json& j, std::uint64_t id) {
  if (!j.is_object()) throw BodyError{"a body must be an object"};
  onlyKeys(j,
           {"name", "shape", "mass", "density", "kinematic", "position", "orientation",
            "linearVelocity", "angularVelocity", "friction", "restitution"},
           "");
  if (!j.contains("shape")) throw BodyError{"missing 'shape'"};
  Vec3 offset{};
  msg::Shape shape = parseShape(j["shape"], offset);
  const bool kinematic = j.value("kinematic", false);
  Vec3 position = j.contains("position") ? vector<3>(j["position"], "position") : Vec3{};
  Quat orientation =
      j.contains("orientation") ? vector<4>(j["orientation"], "orientation") : Quat{0, 0, 0, 1};
  const double norm = std::sqrt(orientation[0] * orientation[0] + orientation[1] * orientation[1] +
                                orientation[2] * orientation[2] + orientation[3] * orientation[3]);
  if (!(norm > 1e-9)) throw BodyError{"'orientation' must be a non-zero quaternion [x, y, z, w]"};
  for (auto& c : orientation) c /= norm;
  if (shape.kind == msg::ShapeKind::TriangleMesh && !kinematic) {
    // A moving mesh collides as itself and weighs what it encloses: it must be closed, and its
    // body frame is centred on its volume centroid like a hull's.
    auto centred = centredMesh(shape, &offset);
    if (!centred) throw BodyError{"dynamic triangle mesh: " + centred.error().message};
    shape = std::move(centred.value());
  }
  // A recentred hull or mesh keeps its points where the file put them.
  asEigen(position) += asEigen(orientation) * asEigen(offset);
  Body body;
  if (kinematic) {
    if (j.contains("mass") || j.contains("density"))
      throw BodyError{"a kinematic body takes no 'mass' or 'density'"};
    body = makeKinematic(id, shape, position, orientation);
  } else {
    if (j.contains("mass") == j.contains("density"))
      throw BodyError{"give exactly one of 'mass' and 'density'"};
    double mass = 0;
    if (j.contains("mass")) {
      mass = number(j["mass"], "mass");
    } else {
      mass = number(j["density"], "density") * msg::massProperties(shape, 1.0).volume;
    }
    if (!(mass > 0)) throw BodyError{"mass (or density) must be positive"};
    body = makeBody(id, shape, mass, position, orientation);
  }
  if (j.contains("linearVelocity"))
    body.linearVelocity = vector<3>(j["linearVelocity"], "linearVelocity");
  if (j.contains("angularVelocity"))
    body.angularVelocity = vector<3>(j["angularVelocity"], "angularVelocity");
  if (j.contains("friction")) {
    body.friction = number(j["friction"], "friction");
    if (!(body.friction >= 0 && body.friction <= 10))
      throw BodyError{"'friction' must be between 0 and 10"};
  }
  if (j.contains("restitution")) {
    body.restitution = number(j["restitution"], "restitution");
    if (!(body.restitution >= 0 && body.restitution <= 1))
      throw BodyError{"'restitution' must be between 0 and 1"};
  }
  return body;
}

// Finds the line where the i-th element of the "bodies" array starts (best effort).
std::size_t bodyLine(std::string_view text, std::size_t index) {
  const auto key = text.find("\"bodies\"");
  if (key == std::string_view::npos) return 0;
  auto at = text.find('[', key);
  if (at == std::string_view::npos) return 0;
  int depth = 0;
  std::size_t count = 0;
  bool inString = false;
  for (std::size_t i = at + 1; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        inString = false;
      continue;
    }
    if (c == '"') inString = true;
    if (depth == 0 && !std::isspace(static_cast<unsigned char>(c)) && c != ',') {
      if (c == ']') return 0;
      if (count == index) return lineOf(text, i);
      ++count;
    }
    if (c == '{' || c == '[') ++depth;
    if (c == '}' || c == ']') --depth;
  }
  return 0;
}

}  // namespace

Result<msg::Shape> convexHullFromPoints(const std::vector<Vec3>& input, Vec3* centroid) {
  if (input.size() < 4) return makeError("a convex hull needs at least 4 points");
  std::vector<double> coords;
  for (const auto& p : input) coords.insert(coords.end(), p.begin(), p.end());
  btConvexHullComputer computer;
  computer.compute(coords.data(), 3 * static_cast<int>(sizeof(double)),
                   static_cast<int>(input.size()), 0, 0);
  if (computer.vertices.size() < 4 || computer.faces.size() < 4)
    return makeError("the convex hull's points are flat (coplanar or collinear)");
  std::vector<Eigen::Vector3d> vertices;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < computer.vertices.size(); ++i) {
    // The hull computer works in btScalar (float): take the exact input point it came from.
    const auto& v = computer.vertices[i];
    const Eigen::Vector3d approx{v.x(), v.y(), v.z()};
    std::size_t best = 0;
    double bestDistance = 1e300;
    for (std::size_t k = 0; k < input.size(); ++k) {
      const double squared = (asEigen(input[k]) - approx).squaredNorm();
      if (squared < bestDistance) bestDistance = squared, best = k;
    }
    vertices.push_back(asEigen(input[best]));
    mean += vertices.back();
  }
  mean *= 1.0 / static_cast<double>(vertices.size());
  std::vector<std::uint32_t> triangles;
  for (int f = 0; f < computer.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &computer.edges[computer.faces[f]];
    std::vector<int> loop;
    const btConvexHullComputer::Edge* e = first;
    do {
      loop.push_back(e->getSourceVertex());
      e = e->getNextEdgeOfFace();
    } while (e != first);
    for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
      std::array<int, 3> t{loop[0], loop[k], loop[k + 1]};
      const Eigen::Vector3d& a = vertices[static_cast<std::size_t>(t[0])];
      const Eigen::Vector3d normal = (vertices[static_cast<std::size_t>(t[1])] - a)
                                         .cross(vertices[static_cast<std::size_t>(t[2])] - a);
      if (normal.dot(a - mean) < 0) std::swap(t[1], t[2]);
      for (int i : t) triangles.push_back(static_cast<std::uint32_t>(i));
    }
  }
  auto centre = volumeCentroid(vertices, triangles);
  if (!centre) return makeError("the convex hull has no volume");
  const Eigen::Vector3d shift = *centre;
  std::vector<double> xyz;
  for (const auto& v : vertices) {
    const Eigen::Vector3d r = v - shift;
    xyz.insert(xyz.end(), r.data(), r.data() + 3);
  }
  if (centroid) *centroid = msg::toVec3(shift);
  return msg::Shape::convexHull(std::move(xyz), std::move(triangles));
}

Result<std::vector<Body>> parseScene(std::string_view text, const std::string& origin) {
  json doc;
  try {
    doc = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    return makeError(origin + ":" + std::to_string(lineOf(text, e.byte > 0 ? e.byte - 1 : 0)) +
                     ": invalid JSON: " + e.what());
  }
  if (!doc.is_object() || !doc.contains("bodies") || !doc["bodies"].is_array())
    return makeError(origin + ":1: a scene is a JSON object with a \"bodies\" array");
  for (auto it = doc.begin(); it != doc.end(); ++it)
    if (it.key() != "bodies" && it.key() != "comment")
      return makeError(origin + ":1: unknown key '" + it.key() + "' (bodies, comment)");
  std::vector<Body> bodies;
  const auto& list = doc["bodies"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    try {
      bodies.push_back(parseBody(list[i], i + 1));
    } catch (const BodyError& e) {
      std::string name;
      if (list[i].is_object() && list[i].contains("name") && list[i]["name"].is_string())
        name = " '" + list[i]["name"].get<std::string>() + "'";
      const std::size_t line = bodyLine(text, i);
      return makeError(origin + ":" + (line > 0 ? std::to_string(line) + ":" : std::string()) +
                       " body " + std::to_string(i) + name + ": " + e.message);
    } catch (const json::exception& e) {
      return makeError(origin + ": body " + std::to_string(i) + ": " + e.what());
    }
  }
  return bodies;
}

Result<std::vector<Body>> loadScene(const std::string& path) {
  Result<std::string> text = readRegularFile(path, kMaxDataFileBytes);
  if (!text) return makeError(path + ": scene file: " + text.error().message);
  return parseScene(*text, path);
}

namespace {

// A small deterministic generator (no std:: distributions, whose output varies by library).
struct Lcg {
  std::uint64_t state;
  double next() {  // [0, 1)
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0);
  }
};

Quat axisAngle(const Vec3& axis, double angle) {
  const Eigen::Vector3d unit = asEigen(axis) * (1.0 / asEigen(axis).norm());
  return msg::toQuat(Eigen::Quaterniond(Eigen::AngleAxisd(angle, unit)));
}

}  // namespace

Result<std::vector<Body>> generateScene(std::string_view spec) {
  const auto colon = spec.find(':');
  if (colon == std::string_view::npos)
    return makeError("generator '" + std::string(spec) +
                     "': expected KIND:N (boxes:N, mixed:N, stack:N, bowls:N)");
  const std::string_view kind = spec.substr(0, colon), countText = spec.substr(colon + 1);
  std::int64_t count = 0;
  const auto [end, ec] =
      std::from_chars(countText.data(), countText.data() + countText.size(), count);
  if (ec != std::errc() || end != countText.data() + countText.size() || count < 1 ||
      count > 1000000)
    return makeError("generator '" + std::string(spec) +
                     "': N must be an integer from 1 to 1000000");
  const auto n = static_cast<std::size_t>(count);
  std::vector<Body> bodies;
  std::uint64_t id = 1;
  Lcg random{12345};
  if (kind == "stack") {
    bodies.push_back(makeKinematic(id++, msg::Shape::box({5, 0.5, 5}), {0, -0.5, 0}));
    for (std::size_t i = 0; i < n; ++i)
      bodies.push_back(makeBody(id++, msg::Shape::box({0.25, 0.25, 0.25}), 1.0,
                                {0, 0.25 + 0.5 * static_cast<double>(i), 0}));
  } else if (kind == "boxes") {
    const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
    const double spacing = 0.6, half = 0.5 * spacing * static_cast<double>(side) + 1.0;
    bodies.push_back(makeKinematic(id++, msg::Shape::box({half, 0.5, half}), {0, -0.5, 0}));
    for (std::size_t i = 0; i < n; ++i) {
      const double x =
          (static_cast<double>(i % side) - 0.5 * static_cast<double>(side - 1)) * spacing;
      const double z =
          (static_cast<double>(i / side) - 0.5 * static_cast<double>(side - 1)) * spacing;
      const double y = 0.3 + 0.5 * random.next();
      const Quat q = axisAngle({random.next() - 0.5, 1.0, random.next() - 0.5},
                               6.283185307179586 * random.next());
      bodies.push_back(makeBody(id++, msg::Shape::box({0.2, 0.2, 0.2}), 1.0, {x, y, z}, q));
    }
  } else if (kind == "mixed") {
    // A 2 m x 2 m box: ground and four 1 m high walls, all kinematic.
    bodies.push_back(makeKinematic(id++, msg::Shape::box({1.6, 0.5, 1.6}), {0, -0.5, 0}));
    bodies.push_back(makeKinematic(id++, msg::Shape::box({0.1, 0.5, 1.2}), {-1.1, 0.5, 0}));
    bodies.push_back(makeKinematic(id++, msg::Shape::box({0.1, 0.5, 1.2}), {1.1, 0.5, 0}));
    bodies.push_back(makeKinematic(id++, msg::Shape::box({1.2, 0.5, 0.1}), {0, 0.5, -1.1}));
    bodies.push_back(makeKinematic(id++, msg::Shape::box({1.2, 0.5, 0.1}), {0, 0.5, 1.1}));
    auto hull = convexHullFromPoints({{0.18, 0, 0},
                                      {-0.12, 0.02, 0.1},
                                      {-0.1, -0.03, -0.12},
                                      {0.02, 0.16, 0.01},
                                      {0.01, -0.14, 0.03},
                                      {0.05, 0.04, 0.15},
                                      {0.06, -0.02, -0.15}});
    if (!hull) return hull.error();
    const double density = 500;
    for (std::size_t i = 0; i < n; ++i) {
      msg::Shape shape;
      switch (i % 4) {
        case 0:
          shape = msg::Shape::sphere(0.15);
          break;
        case 1:
          shape = msg::Shape::box({0.15, 0.12, 0.1});
          break;
        case 2:
          shape = msg::Shape::capsule(0.1, 0.12);
          break;
        default:
          shape = hull.value();
          break;
      }
      const std::size_t layer = i / 9, cell = i % 9;
      const Vec3 position{-0.5 + 0.5 * static_cast<double>(cell % 3) + 0.1 * (random.next() - 0.5),
                          0.5 + 0.55 * static_cast<double>(layer),
                          -0.5 + 0.5 * static_cast<double>(cell / 3) + 0.1 * (random.next() - 0.5)};
      const Quat q = axisAngle({random.next() - 0.5, random.next() - 0.5, random.next() + 0.1},
                               6.283185307179586 * random.next());
      bodies.push_back(
          makeBody(id++, shape, density * msg::massProperties(shape, 1.0).volume, position, q));
    }
  } else if (kind == "bowls") {
    // Bowls (dynamic concave meshes) in a row on the ground, each catching a sphere and a box.
    const double spacing = 1.0, half = 0.5 * spacing * static_cast<double>(n) + 1.0;
    bodies.push_back(makeKinematic(id++, msg::Shape::box({half, 0.5, 1.5}), {0, -0.5, 0}));
    Vec3 centroid{};
    auto bowl = centredMesh(bowlMesh(0.3, 0.3, 0.05), &centroid);
    if (!bowl) return bowl.error();
    const double density = 500;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1)) * spacing;
      bodies.push_back(makeBody(id++, bowl.value(),
                                density * msg::massProperties(bowl.value(), 1.0).volume,
                                {x + centroid[0], centroid[1], centroid[2]}));
      bodies.push_back(makeBody(id++, msg::Shape::sphere(0.08), 1.0,
                                {x + 0.1 * (random.next() - 0.5), 0.6, 0.05}));
      bodies.push_back(makeBody(id++, msg::Shape::box({0.06, 0.06, 0.06}), 0.5,
                                {x + 0.1 * (random.next() - 0.5), 0.9, -0.08}));
    }
  } else {
    return makeError("generator '" + std::string(spec) + "': unknown kind '" + std::string(kind) +
                     "' (boxes, mixed, stack, bowls)");
  }
  return bodies;
}

}  // namespace vrflow::rigid
