// viewer-testing/bodies: a tiny scene for the viewer's end-to-end tests, no physics. Iteration 0
// sends the shapes (static resources) and adds a box, a sphere and a 6 x 6 net; later iterations
// update only the positions (the box sinks, the sphere moves along x, the net waves). Ends after
// `count` iterations; deletes the sphere at `delete-at`; with `forged` it also adds an object
// whose shape resource is forged.
#include <cmath>
#include <cstdio>
#include <span>
#include <vector>

#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/shape.hpp"
#include "vrflow/module/module.hpp"

int main() {
  using namespace vrflow;
  Module module;
  auto& out = module.addOutput("objects");
  if (auto status = module.init(); !status) {
    std::fprintf(stderr, "%s\n", status.error().message.c_str());
    return 2;
  }
  const auto count = static_cast<std::uint64_t>(module.params().getInt("count"));
  const auto deleteAt = module.params().getInt("delete-at");
  const bool forged = module.params().getBool("forged");
  const std::uint64_t boxShape = module.newId(), sphereShape = module.newId();
  const std::uint64_t forgedShape = module.newId();
  const std::uint64_t box = module.newId(), sphere = module.newId(), net = module.newId();
  const std::uint64_t ghost = module.newId();
  constexpr int kSide = 6;
  std::vector<std::uint32_t> surface;
  for (std::uint32_t j = 0; j + 1 < kSide; ++j) {
    for (std::uint32_t i = 0; i + 1 < kSide; ++i) {
      const std::uint32_t a = j * kSide + i;
      surface.insert(surface.end(), {a, a + kSide, a + 1, a + 1, a + kSide, a + kSide + 1});
    }
  }
  std::vector<double> masses(kSide * kSide * 3);
  // wait() only for an iteration it will do: leaving the loop counts the one in progress.
  for (std::uint64_t done = 0; (done < count) && module.wait(); ++done) {
    const std::uint64_t it = module.iteration();
    const double t = static_cast<double>(it);
    for (int j = 0; j < kSide; ++j) {
      for (int i = 0; i < kSide; ++i) {
        double* p = &masses[static_cast<std::size_t>(3 * (j * kSide + i))];
        p[0] = -2.5 + 0.4 * i;
        p[1] = 2.0 + 0.15 * std::sin(0.8 * i + 0.5 * t);
        p[2] = -1.0 + 0.4 * j;
      }
    }
    const msg::Vec3 boxAt{0.0, 1.5 - 0.1 * t, 0.0};
    const msg::Vec3 sphereAt{1.5 + 0.2 * t, 0.5, 0.0};
    auto message = module.newMessage(8192);
    auto& b = message.builder();
    const auto op = it == 0 ? msg::ObjectOp::Add : msg::ObjectOp::Update;
    if (it == 0) {
      const auto boxBytes = msg::encodeShape(msg::Shape::box({0.5, 0.5, 0.5}));
      const auto sphereBytes = msg::encodeShape(msg::Shape::sphere(0.5));
      b.addRawResource(boxShape, false, boxBytes);
      b.addRawResource(sphereShape, false, sphereBytes);
      b.addObject(box, msg::rigidType(), op)
          .set(msg::RigidParam::kPosition, boxAt)
          .set(msg::RigidParam::kOrientation, msg::Quat{0, std::sin(0.3), 0, std::cos(0.3)})
          .set(msg::RigidParam::kShape, boxShape);
      b.addObject(sphere, msg::rigidType(), op)
          .set(msg::RigidParam::kPosition, sphereAt)
          .set(msg::RigidParam::kOrientation, msg::Quat{0, 0, 0, 1})
          .set(msg::RigidParam::kShape, sphereShape);
      b.addObject(net, msg::massSpringType(), op)
          .set(msg::MassSpringParam::kPositions, std::span<const double>(masses))
          .set(msg::MassSpringParam::kSurface, std::as_bytes(std::span(surface)));
      if (forged) {
        auto bytes = msg::encodeShape(msg::Shape::box({1, 1, 1}));
        bytes.resize(30);  // truncated
        b.addRawResource(forgedShape, false, bytes);
        b.addObject(ghost, msg::rigidType(), op)
            .set(msg::RigidParam::kPosition, msg::Vec3{0, 1, 0})
            .set(msg::RigidParam::kShape, forgedShape);
      }
    } else {
      b.addObject(box, msg::rigidType(), op).set(msg::RigidParam::kPosition, boxAt);
      if (deleteAt >= 0 && it == static_cast<std::uint64_t>(deleteAt)) {
        b.addDelete(sphere, msg::rigidType());
      } else if (deleteAt < 0 || it < static_cast<std::uint64_t>(deleteAt)) {
        b.addObject(sphere, msg::rigidType(), op).set(msg::RigidParam::kPosition, sphereAt);
      }
      b.addObject(net, msg::massSpringType(), op)
          .set(msg::MassSpringParam::kPositions, std::span<const double>(masses));
    }
    if (!module.put(out, std::move(message))) break;
  }
  return module.exitStatus();
}
