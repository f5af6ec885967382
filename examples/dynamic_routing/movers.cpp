// routing/movers: a synthetic scene of rigid bodies moving along x across a world of width
// `width` (wrapping around), spread over y. Iteration 0 sends `meshes` mesh resources (static)
// and every body's full state (add: position, orientation, velocities, mass, inertia, bounds,
// shape = one of the meshes); later iterations update position, linear velocity and bounds.
// `meshes-at` sends the meshes at a later iteration instead (after the bodies that use them);
// `delete-at` deletes body 0 at that iteration (0: never). `dynamic-meshes` makes the meshes
// dynamic resources sent again every iteration (from `meshes-at` on) with vertex 0's x equal to
// the iteration, so that a receiver can tell which copy it holds.
// Body i: size 1, x = (i * 7.3 + speed_i * t) mod width with speed_i = 0.5 + (i mod 5) * 0.25,
// y = (i mod 8) * 1.5, z = 0; t = iteration * dt.
#include <cmath>
#include <cstdio>
#include <vector>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& objects = module.addOutput("objects");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "routing-movers: %s\n", status.error().message.c_str());
    return 2;
  }
  const auto count = static_cast<std::size_t>(module.params().getInt("count"));
  const auto meshCount = static_cast<std::size_t>(module.params().getInt("meshes"));
  const auto iterations = static_cast<uint64_t>(module.params().getInt("iterations"));
  const double width = module.params().getFloat("width");
  const double dt = module.params().getFloat("dt");
  const auto triangles = static_cast<std::size_t>(module.params().getInt("mesh-triangles"));
  const auto meshesAt = static_cast<uint64_t>(module.params().getInt("meshes-at"));
  const auto deleteAt = static_cast<uint64_t>(module.params().getInt("delete-at"));
  const bool dynamicMeshes = module.params().getBool("dynamic-meshes");

  std::vector<uint64_t> meshIds, bodyIds;
  for (std::size_t m = 0; m < meshCount; ++m) meshIds.push_back(module.newId());
  for (std::size_t i = 0; i < count; ++i) bodyIds.push_back(module.newId());
  const auto& rigid = msg::rigidType();
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (uint64_t done = 0; (iterations == 0 || done < iterations) && module.wait(); ++done) {
    const uint64_t it = module.iteration();
    const double t = static_cast<double>(it) * dt;
    auto out = module.newMessage(count * 256 + meshCount * triangles * 48 + 256);
    auto& builder = out.builder();
    builder.setSimTime(t);
    builder.setTimeStep(dt);
    if (it == meshesAt || (dynamicMeshes && it > meshesAt)) {
      for (std::size_t m = 0; m < meshCount; ++m) {  // a fan of triangles, different per mesh
        std::vector<float> xyz;
        std::vector<uint32_t> indices;
        for (std::size_t v = 0; v <= triangles + 1; ++v) {
          const double a = static_cast<double>(v) * 0.1 + static_cast<double>(m);
          xyz.insert(xyz.end(), {static_cast<float>(0.5 * std::cos(a)),
                                 static_cast<float>(0.5 * std::sin(a)), 0.0f});
        }
        for (uint32_t v = 1; v <= triangles; ++v) indices.insert(indices.end(), {0u, v, v + 1});
        if (dynamicMeshes) xyz[0] = static_cast<float>(it);
        builder.addMesh(meshIds[m], dynamicMeshes, xyz, indices);
      }
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (i == 0 && deleteAt != 0 && it >= deleteAt) {
        if (it == deleteAt) builder.addDelete(bodyIds[0], rigid);
        continue;
      }
      const double speed = 0.5 + static_cast<double>(i % 5) * 0.25;
      const double x = std::fmod(static_cast<double>(i) * 7.3 + speed * t, width);
      const double y = static_cast<double>(i % 8) * 1.5;
      const msg::Vec3 position{x, y, 0};
      const msg::Aabb bounds{{x - 0.5, y - 0.5, -0.5}, {x + 0.5, y + 0.5, 0.5}};
      if (it == 0) {
        builder.addObject(bodyIds[i], rigid, msg::ObjectOp::Add)
            .set(msg::RigidParam::kPosition, position)
            .set(msg::RigidParam::kOrientation, msg::Quat{0, 0, 0, 1})
            .set(msg::RigidParam::kLinearVelocity, msg::Vec3{speed, 0, 0})
            .set(msg::RigidParam::kAngularVelocity, msg::Vec3{0, 0, 0})
            .set(msg::RigidParam::kMass, 1.0)
            .set(msg::RigidParam::kInertia, msg::Mat3{1, 0, 0, 0, 1, 0, 0, 0, 1})
            .set(msg::RigidParam::kBounds, bounds)
            .set(msg::RigidParam::kShape, meshIds[i % meshCount]);
      } else {
        builder.addObject(bodyIds[i], rigid, msg::ObjectOp::Update)
            .set(msg::RigidParam::kPosition, position)
            .set(msg::RigidParam::kLinearVelocity, msg::Vec3{speed, 0, 0})
            .set(msg::RigidParam::kBounds, bounds);
      }
    }
    if (!module.put(objects, std::move(out))) break;
  }
  return module.exitStatus();
}
