// Moving (dynamic) triangle meshes: they collide with their own concave surface (GImpact) and
// weigh what they enclose. Checked against analytic answers: where a body must come to rest,
// and the mass and inertia of meshes made of boxes.
#include "vrflow/rigid/mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "vrflow/rigid/scene.hpp"
#include "vrflow/rigid/world.hpp"

namespace vrflow::rigid {
namespace {

constexpr double kDt = 0.01;

RigidWorld gravityWorld() {
  return RigidWorld(ForceField({FieldTerm{FieldTerm::Kind::Gravity, {0, -9.81, 0}}}), {});
}

Body groundBox(std::uint64_t id) {
  return makeKinematic(id, msg::Shape::box({3, 0.5, 3}), {0, -0.5, 0});
}

// A dynamic body whose mesh is given where it lies: recentred on its centroid (as scenes do).
Body meshBody(std::uint64_t id, const msg::Shape& mesh, double density, const Vec3& placement) {
  Vec3 centroid{};
  auto centred = centredMesh(mesh, &centroid);
  EXPECT_TRUE(centred) << (centred ? "" : centred.error().message);
  const Vec3 position = msg::toVec3(asEigen(placement) + asEigen(centroid));
  return makeBody(id, centred.value(), density * msg::massProperties(centred.value(), 1.0).volume,
                  position);
}

// A closed mesh of an axis-aligned box [lo, hi].
msg::Shape boxMesh(const Vec3& lo, const Vec3& hi) {
  QuadMeshBuilder m;
  std::uint32_t c[8];
  for (std::uint32_t i = 0; i < 8; ++i)
    c[i] = m.vertex({(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]});
  m.quad(c[0], c[2], c[6], c[4], {-1, 0, 0});
  m.quad(c[1], c[3], c[7], c[5], {1, 0, 0});
  m.quad(c[0], c[1], c[5], c[4], {0, -1, 0});
  m.quad(c[2], c[3], c[7], c[6], {0, 1, 0});
  m.quad(c[0], c[1], c[3], c[2], {0, 0, -1});
  m.quad(c[4], c[5], c[7], c[6], {0, 0, 1});
  return m.shape();
}

// A U-shaped prism in the x-y plane, `a` the width of its three 1 x 1 / 1 x 2 / 1 x 2 bars
// (bottom bar x in [0, 3a], y in [0, a]; posts x in [0, a] and [2a, 3a], y in [a, 3a]), z in
// [0, depth]. Upside down (`arch`), the posts point down: y in [0, 3a] with the bar on top.
msg::Shape uPrism(double a, double depth, bool arch) {
  QuadMeshBuilder m;
  const double xy[8][2] = {{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
  std::uint32_t front[8], back[8];
  for (int i = 0; i < 8; ++i) {
    const double y = arch ? 3 * a - a * xy[i][1] : a * xy[i][1];
    front[i] = m.vertex({a * xy[i][0], y, depth});
    back[i] = m.vertex({a * xy[i][0], y, 0});
  }
  // The caps as three convex quads; the sides one quad per polygon edge.
  const int caps[3][4] = {{0, 1, 4, 5}, {1, 2, 3, 4}, {0, 5, 6, 7}};
  for (const auto& q : caps) {
    m.quad(front[q[0]], front[q[1]], front[q[2]], front[q[3]], {0, 0, 1});
    m.quad(back[q[0]], back[q[1]], back[q[2]], back[q[3]], {0, 0, -1});
  }
  for (int i = 0; i < 8; ++i) {
    const int j = (i + 1) % 8;
    // Counter-clockwise polygon: the outward normal is the edge turned clockwise (flipped with
    // the arch's mirrored y).
    const double ex = xy[j][0] - xy[i][0], ey = xy[j][1] - xy[i][1];
    m.quad(back[i], back[j], front[j], front[i], {ey, arch ? ex : -ex, 0});
  }
  return m.shape();
}

// A square ring (a torus-like frame): outer half width `outer`, inner `inner`, y in [0, h].
msg::Shape squareRing(double outer, double inner, double h) {
  QuadMeshBuilder m;
  const double sx[4] = {-1, 1, 1, -1}, sz[4] = {-1, -1, 1, 1};
  std::uint32_t ob[4], ot[4], ib[4], it[4];
  for (int k = 0; k < 4; ++k) {
    ob[k] = m.vertex({outer * sx[k], 0, outer * sz[k]});
    ot[k] = m.vertex({outer * sx[k], h, outer * sz[k]});
    ib[k] = m.vertex({inner * sx[k], 0, inner * sz[k]});
    it[k] = m.vertex({inner * sx[k], h, inner * sz[k]});
  }
  for (int k = 0; k < 4; ++k) {
    const int n = (k + 1) % 4;
    const Vec3 side{sx[k] + sx[n], 0, sz[k] + sz[n]};
    m.quad(ob[k], ob[n], ot[n], ot[k], side);
    m.quad(ib[k], ib[n], it[n], it[k], {-side[0], 0, -side[2]});
    m.quad(ot[k], ot[n], it[n], it[k], {0, 1, 0});
    m.quad(ob[k], ob[n], ib[n], ib[k], {0, -1, 0});
  }
  return m.shape();
}

// Boxes [lo, hi] of sign +1 (solid) or -1 (a cavity cut from the solid ones).
struct SignedBox {
  Vec3 lo, hi;
  double sign;
};

// The analytic volume, centroid and inertia (about the centroid, density 1) of signed boxes.
void boxesMassProperties(const std::vector<SignedBox>& boxes, double& volume,
                         Eigen::Vector3d& centroid, Eigen::Matrix3d& inertia) {
  volume = 0;
  centroid.setZero();
  for (const auto& b : boxes) {
    const Eigen::Vector3d size = asEigen(b.hi) - asEigen(b.lo);
    const double v = b.sign * size.prod();
    volume += v;
    centroid += v * 0.5 * (asEigen(b.lo) + asEigen(b.hi));
  }
  centroid /= volume;
  inertia.setZero();
  for (const auto& b : boxes) {
    const Eigen::Vector3d size = asEigen(b.hi) - asEigen(b.lo);
    const double v = b.sign * size.prod();
    const Eigen::Vector3d s2 = size.cwiseProduct(size);
    Eigen::Matrix3d own = Eigen::Matrix3d::Zero();
    own.diagonal() << s2[1] + s2[2], s2[0] + s2[2], s2[0] + s2[1];
    const Eigen::Vector3d d = 0.5 * (asEigen(b.lo) + asEigen(b.hi)) - centroid;
    inertia +=
        v / 12.0 * own + v * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
}

// The scene file's body for a mesh, with a density.
nlohmann::json meshJson(const msg::Shape& mesh, double density, const Vec3& position) {
  nlohmann::json vertices = nlohmann::json::array(), triangles = nlohmann::json::array();
  for (std::size_t i = 0; i < mesh.vertices.size(); i += 3)
    vertices.push_back({mesh.vertices[i], mesh.vertices[i + 1], mesh.vertices[i + 2]});
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3)
    triangles.push_back({mesh.indices[i], mesh.indices[i + 1], mesh.indices[i + 2]});
  return {{"name", "mesh"},
          {"shape", {{"type", "triangleMesh"}, {"vertices", vertices}, {"triangles", triangles}}},
          {"density", density},
          {"position", {position[0], position[1], position[2]}}};
}

TEST(RigidMesh, MeshesMadeOfBoxesHaveTheAnalyticMassCentroidAndInertia) {
  const double density = 700;
  const Vec3 placement{0.3, -0.2, 1.1};
  struct Case {
    const char* name;
    msg::Shape mesh;
    std::vector<SignedBox> boxes;
  };
  const double a = 0.1, depth = 0.25;
  const std::vector<Case> cases = {
      {"U prism",
       uPrism(a, depth, false),
       {{{0, 0, 0}, {3 * a, a, depth}, 1},
        {{0, a, 0}, {a, 3 * a, depth}, 1},
        {{2 * a, a, 0}, {3 * a, 3 * a, depth}, 1}}},
      {"square ring",
       squareRing(0.4, 0.25, 0.1),
       {{{-0.4, 0, -0.4}, {0.4, 0.1, -0.25}, 1},
        {{-0.4, 0, 0.25}, {0.4, 0.1, 0.4}, 1},
        {{-0.4, 0, -0.25}, {-0.25, 0.1, 0.25}, 1},
        {{0.25, 0, -0.25}, {0.4, 0.1, 0.25}, 1}}},
      {"bowl",
       bowlMesh(0.3, 0.25, 0.04),
       {{{-0.3, 0, -0.3}, {0.3, 0.25, 0.3}, 1}, {{-0.26, 0.04, -0.26}, {0.26, 0.25, 0.26}, -1}}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const nlohmann::json scene = {{"bodies", {meshJson(c.mesh, density, placement)}}};
    auto bodies = parseScene(scene.dump(1), "scene.json");
    ASSERT_TRUE(bodies) << bodies.error().message;
    const Body& body = bodies->front();
    double volume = 0;
    Eigen::Vector3d centroid;
    Eigen::Matrix3d inertia;
    boxesMassProperties(c.boxes, volume, centroid, inertia);
    EXPECT_NEAR(body.mass, density * volume, 1e-9 * density * volume);
    // The body frame's origin is the centroid; the vertices stay where the file put them.
    EXPECT_LT((asEigen(body.position) - (asEigen(placement) + centroid)).norm(), 1e-12);
    const Eigen::Matrix3d expected = density * inertia;
    const Eigen::Matrix3d actual = asEigen(body.inertia);
    EXPECT_LT((actual - expected).norm(), 1e-6 * expected.norm()) << "mesh inertia\n"
                                                                  << actual << "\nanalytic\n"
                                                                  << expected;
  }
}

// The bowl on the ground catches a sphere: the sphere comes to rest on the cavity's floor, well
// below the rim (the bowl's convex hull would hold it on top, at rim + radius).
TEST(RigidMesh, SphereDroppedIntoABowlRestsInsideBelowItsRim) {
  const double half = 0.3, height = 0.3, wall = 0.05, r = 0.08;
  RigidWorld world = gravityWorld();
  const Body bowl = meshBody(2, bowlMesh(half, height, wall), 500, {0, 0, 0});
  ASSERT_TRUE(
      world.add({groundBox(1), bowl, makeBody(3, msg::Shape::sphere(r), 1.0, {0.04, 0.7, -0.03})}));
  double lowestBowl = 1e9;
  for (int i = 0; i < 300; ++i) {
    world.step(kDt);
    const Body& b = *world.state().find(2);
    lowestBowl = std::min(lowestBowl, msg::worldBounds(b.shape, b.position, b.orientation).min[1]);
  }
  const Body& sphere = *world.state().find(3);
  const Body& b = *world.state().find(2);
  // On the cavity floor (y = wall), within the margins, and inside the walls.
  EXPECT_LT(sphere.position[1], height);
  EXPECT_NEAR(sphere.position[1], wall + r, 0.012);
  EXPECT_LT(std::abs(sphere.position[0] - b.position[0]), half - wall - r + 0.01);
  EXPECT_LT(std::abs(sphere.position[2] - b.position[2]), half - wall - r + 0.01);
  EXPECT_LT(asEigen(sphere.linearVelocity).norm(), 0.02);
  // The bowl stands on the ground, upright, and barely moved.
  const auto box = msg::worldBounds(b.shape, b.position, b.orientation);
  EXPECT_NEAR(box.min[1], 0.0, 0.012);
  EXPECT_GT(lowestBowl, -0.02);
  EXPECT_GT(std::abs(b.orientation[3]), 0.9999);
  EXPECT_LT(std::hypot(b.position[0] - bowl.position[0], b.position[2] - bowl.position[2]), 0.02);
}

// An arch (a U prism upside down, 0.1 m slot 0.2 m high) falls over a 0.12 m high block: its two
// feet land on the ground on either side of the block (as its hull it would sit on the block).
TEST(RigidMesh, ArchFallingOverABlockStandsOnBothFeet) {
  const double a = 0.1, depth = 0.2;
  RigidWorld world = gravityWorld();
  const Body arch = meshBody(3, uPrism(a, depth, true), 600, {0, 0.15, 0});
  const Body block = makeKinematic(2, msg::Shape::box({0.03, 0.06, 0.08}), {0.15, 0.06, 0.1});
  ASSERT_TRUE(world.add({groundBox(1), block, arch}));
  for (int i = 0; i < 300; ++i) world.step(kDt);
  const Body& b = *world.state().find(3);
  const auto box = msg::worldBounds(b.shape, b.position, b.orientation);
  EXPECT_NEAR(box.min[1], 0.0, 0.012) << "the arch's feet should stand on the ground";
  EXPECT_NEAR(box.max[1], 3 * a, 0.012);
  EXPECT_GT(std::abs(b.orientation[3]), 0.9999) << "the arch should stand level";
  EXPECT_NEAR(b.position[0], arch.position[0], 0.01);
  EXPECT_LT(asEigen(b.linearVelocity).norm(), 0.02);
}

// Mesh against mesh and against a static mesh: a bowl standing on a static two-triangle floor
// catches a closed cube mesh, which rests on the bowl's floor.
TEST(RigidMesh, CubeMeshRestsInABowlStandingOnAStaticMeshFloor) {
  const double half = 0.3, height = 0.3, wall = 0.05, side = 0.12;
  const auto floor =
      msg::Shape::triangleMesh({-3, 0, -3, 3, 0, -3, 3, 0, 3, -3, 0, 3}, {0, 2, 1, 0, 3, 2});
  RigidWorld world = gravityWorld();
  const Body bowl = meshBody(2, bowlMesh(half, height, wall), 500, {0, 0, 0});
  const Body cube = meshBody(3, boxMesh({-side / 2, 0, -side / 2}, {side / 2, side, side / 2}), 400,
                             {0.02, 0.5, 0.03});
  ASSERT_TRUE(world.add({makeKinematic(1, floor, {0, 0, 0}), bowl, cube}));
  for (int i = 0; i < 300; ++i) world.step(kDt);
  const Body& bw = *world.state().find(2);
  const Body& c = *world.state().find(3);
  const auto bowlBox = msg::worldBounds(bw.shape, bw.position, bw.orientation);
  const auto cubeBox = msg::worldBounds(c.shape, c.position, c.orientation);
  EXPECT_NEAR(bowlBox.min[1], 0.0, 0.015);
  EXPECT_NEAR(cubeBox.min[1], wall, 0.015) << "the cube should rest on the bowl's floor";
  EXPECT_LT(cubeBox.max[1], height);
  EXPECT_LT(asEigen(c.linearVelocity).norm(), 0.02);
  EXPECT_LT(asEigen(bw.linearVelocity).norm(), 0.02);
}

// A moving mesh's contacts start as far away as the other shapes' (the speculative distance,
// 4 cm): a ball above the bowl's floor and a bowl above a static mesh floor get a contact whose
// distance is the gap, as a ball above a box does.
TEST(RigidMesh, MovingMeshGetsSpeculativeContactsAsFarAsOtherShapes) {
  const auto floor =
      msg::Shape::triangleMesh({-3, 0, -3, 3, 0, -3, 3, 0, 3, -3, 0, 3}, {0, 2, 1, 0, 3, 2});
  for (double gap : {0.008, 0.02, 0.035}) {
    SCOPED_TRACE(gap);
    RigidContactSolver solver(ContactParams{});
    const Body bowl = meshBody(1, bowlMesh(0.3, 0.3, 0.05), 500, {0, gap, 0});
    ASSERT_TRUE(solver.setBody(bowl));
    ASSERT_TRUE(solver.setBody(makeKinematic(2, floor, {0, 0, 0})));
    ASSERT_TRUE(solver.setBody(
        makeBody(3, msg::Shape::sphere(0.08), 1.0, {0, gap + 0.05 + 0.08 + gap, 0})));
    ASSERT_TRUE(solver.setBody(makeKinematic(4, msg::Shape::box({0.1, 0.1, 0.1}), {2, 0, 0})));
    ASSERT_TRUE(
        solver.setBody(makeBody(5, msg::Shape::sphere(0.08), 1.0, {2, 0.1 + 0.08 + gap, 0})));
    solver.solve(kDt);
    bool ballInBowl = false, bowlOnFloor = false, ballOnBox = false;
    for (const auto& c : solver.contacts()) {
      const auto pair = std::minmax(c.a, c.b);
      // Bullet's distances are floats; the bowl's triangles carry the 5 mm margin.
      if (pair == std::minmax<std::uint64_t>(1, 3))
        ballInBowl |= std::abs(c.distance - gap) < 1e-4 + 0.005;
      if (pair == std::minmax<std::uint64_t>(1, 2))
        bowlOnFloor |= std::abs(c.distance - gap) < 1e-4 + 0.005;
      if (pair == std::minmax<std::uint64_t>(4, 5)) ballOnBox |= std::abs(c.distance - gap) < 1e-4;
    }
    EXPECT_TRUE(ballOnBox);
    EXPECT_TRUE(ballInBowl);
    EXPECT_TRUE(bowlOnFloor);
  }
}

std::string errorOf(const Result<std::vector<Body>>& result) {
  return result ? std::string("(no error)") : result.error().message;
}

// A dynamic mesh that encloses no volume is one clear error naming the file, line and body; a
// kinematic one may be open.
TEST(RigidMesh, OpenInconsistentDegenerateOrFlatDynamicMeshIsAnErrorNamingTheBody) {
  const msg::Shape bowl = bowlMesh(0.3, 0.3, 0.05);
  const auto sceneWith = [](const msg::Shape& mesh, bool kinematic) {
    nlohmann::json body = meshJson(mesh, 500, {0, 0, 0});
    body["name"] = "bowl";
    if (kinematic) {
      body.erase("density");
      body["kinematic"] = true;
    }
    const nlohmann::json ball = {{"shape", {{"type", "sphere"}, {"radius", 0.1}}}, {"mass", 1}};
    return nlohmann::json{{"bodies", {ball, body}}}.dump(1);
  };
  msg::Shape open = bowl;
  open.indices.resize(open.indices.size() - 3);
  msg::Shape flipped = bowl;
  std::swap(flipped.indices[1], flipped.indices[2]);
  msg::Shape degenerate = bowl;
  degenerate.vertices.insert(degenerate.vertices.end(), {0.5, 0, 0, 1, 0, 0, 1.5, 0, 0});
  const auto n = static_cast<std::uint32_t>(bowl.vertices.size() / 3);
  degenerate.indices.insert(degenerate.indices.end(), {n, n + 1, n + 2, n, n + 2, n + 1});
  const auto flat = msg::Shape::triangleMesh({0, 0, 0, 1, 0, 0, 0, 0, 1}, {0, 1, 2, 0, 2, 1});
  const std::vector<std::pair<msg::Shape, std::string>> cases = {
      {open, "the mesh is not closed: edge"},
      {flipped, "used twice in the same direction"},
      {degenerate, "triangle 28 is degenerate"},
      {flat, "encloses no volume"},
  };
  for (const auto& [mesh, reason] : cases) {
    const std::string text = sceneWith(mesh, false);
    const auto result = parseScene(text, "scene.json");
    ASSERT_FALSE(result) << reason;
    const std::string& message = result.error().message;
    EXPECT_TRUE(std::regex_search(
        message, std::regex("^scene\\.json:[0-9]+: body 1 'bowl': dynamic triangle mesh: ")))
        << message;
    EXPECT_NE(message.find(reason), std::string::npos) << message;
  }
  // The same open mesh as a kinematic body (a ground, a ramp) is fine.
  EXPECT_TRUE(parseScene(sceneWith(open, true), "scene.json"))
      << errorOf(parseScene(sceneWith(open, true), "scene.json"));

  // A solver fed an open moving mesh directly (a network's object) names the body.
  RigidContactSolver solver(ContactParams{});
  const auto status = solver.setBody(makeBody(5, open, 1.0, {0, 0, 0}));
  ASSERT_FALSE(status);
  EXPECT_NE(status.error().message.find("rigid body 5: dynamic triangle mesh: the mesh is not "
                                        "closed"),
            std::string::npos)
      << status.error().message;
  EXPECT_FALSE(solver.contains(5));
}

// Meshes keep the solver deterministic: the same bowls scene twice gives the same bits.
TEST(RigidMesh, BowlsSceneTwiceGivesIdenticalBits) {
  auto run = [] {
    auto bodies = generateScene("bowls:3");
    EXPECT_TRUE(bodies) << (bodies ? "" : bodies.error().message);
    RigidWorld world = gravityWorld();
    EXPECT_TRUE(world.add(*bodies));
    for (int i = 0; i < 150; ++i) world.step(kDt);
    std::vector<double> out;
    for (const Body& b : world.state().bodies()) {
      out.insert(out.end(), b.position.begin(), b.position.end());
      out.insert(out.end(), b.orientation.begin(), b.orientation.end());
    }
    return out;
  };
  const auto first = run();
  EXPECT_EQ(first, run());
  // And every sphere and box ended inside its bowl (below the 0.3 m rim).
  auto bodies = generateScene("bowls:3");
  ASSERT_TRUE(bodies);
  ASSERT_EQ(bodies->size(), 10u);
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t j : {1u, 2u}) EXPECT_LT(first[7 * (1 + 3 * k + j) + 1], 0.3) << k << j;
}

}  // namespace
}  // namespace vrflow::rigid
