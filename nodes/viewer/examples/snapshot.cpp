// vrflow-viewer-snapshot: renders a fixed sample scene (a box, a sphere, a capsule, a tilted
// box, a net draped between them, fluid particles) from messages in one process and writes one
// PNG. It shows the library without the runtime: build messages, apply them, render, write.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "vrflow/message/builder.hpp"
#include "vrflow/message/builtin_types.hpp"
#include "vrflow/message/byte_sink.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/message/shape.hpp"
#include "vrflow/viewer/renderer.hpp"

namespace {

using namespace vrflow;

void addRigid(msg::MessageBuilder& b, std::uint64_t id, const msg::Vec3& p, const msg::Quat& q,
              std::uint64_t shape) {
  b.addObject(id, msg::rigidType(), msg::ObjectOp::Add)
      .set(msg::RigidParam::kPosition, p)
      .set(msg::RigidParam::kOrientation, q)
      .set(msg::RigidParam::kShape, shape);
}

void addShape(msg::MessageBuilder& b, std::uint64_t id, const msg::Shape& shape) {
  const auto bytes = msg::encodeShape(shape);
  b.addRawResource(id, false, bytes);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: vrflow-viewer-snapshot OUT.png [WIDTH HEIGHT]\n");
    return 2;
  }
  viewer::RenderSettings settings;
  settings.supersample = 2;
  if (argc >= 4) {
    settings.width = std::atoi(argv[2]);
    settings.height = std::atoi(argv[3]);
  }
  msg::VectorSink sink;
  msg::MessageBuilder b(sink);
  addShape(b, 1001, msg::Shape::box({0.5, 0.5, 0.5}));
  addShape(b, 1002, msg::Shape::sphere(0.6));
  addShape(b, 1003, msg::Shape::capsule(0.3, 0.5));
  addShape(b, 1004, msg::Shape::box({0.8, 0.15, 0.4}));
  const double s = std::sqrt(0.5);
  addRigid(b, 1, {-2.0, 0.5, 0.0}, {0, 0, 0, 1}, 1001);
  addRigid(b, 2, {0.2, 0.6, -1.2}, {0, 0, 0, 1}, 1002);
  addRigid(b, 3, {2.2, 0.8, 0.3}, {0, 0, std::sin(0.3), std::cos(0.3)}, 1003);
  addRigid(b, 4, {-0.3, 0.15, 1.6}, {0, std::sin(0.4), 0, std::cos(0.4)}, 1004);
  addRigid(b, 5, {-2.0, 1.4, 0.0}, {0, s * std::sin(0.39), 0, std::cos(0.39)}, 1002);
  // A 20 x 20 net sagging between four corners at height 2.2, over the objects.
  const int n = 20;
  std::vector<double> xyz;
  std::vector<std::uint32_t> triangles;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = i / (n - 1.0), v = j / (n - 1.0);
      const double sag = 0.9 * std::sin(u * M_PI) * std::sin(v * M_PI);
      xyz.insert(xyz.end(), {-1.6 + 3.2 * u, 2.4 - sag, -1.8 + 3.2 * v});
      if (i + 1 < n && j + 1 < n) {
        const auto a = static_cast<std::uint32_t>(j * n + i);
        const auto n32 = static_cast<std::uint32_t>(n);
        triangles.insert(triangles.end(), {a, a + n32, a + 1, a + 1, a + n32, a + n32 + 1});
      }
    }
  }
  b.addObject(6, msg::massSpringType(), msg::ObjectOp::Add)
      .set(msg::MassSpringParam::kPositions, std::span<const double>(xyz))
      .set(msg::MassSpringParam::kSurface, std::as_bytes(std::span(triangles)));
  // A column of fluid particles.
  std::vector<float> particles;
  for (int k = 0; k < 600; ++k) {
    const double a = k * 2.39996, r = 0.35 * std::sqrt((k % 100) / 100.0);
    particles.insert(particles.end(), {static_cast<float>(3.0 + r * std::cos(a)),
                                       static_cast<float>(0.02 + 0.004 * k),
                                       static_cast<float>(-1.5 + r * std::sin(a))});
  }
  b.addMesh(1005, true, particles, {});
  b.addObject(7, msg::fluidType(), msg::ObjectOp::Add)
      .set(msg::FluidParam::kParticles, std::uint64_t{1005});
  const auto size = b.finish();
  auto message = msg::MessageView::parse(std::span(sink.buffer()).first(size));
  if (!message) {
    std::fprintf(stderr, "vrflow-viewer-snapshot: %s\n", message.error().message.c_str());
    return 1;
  }
  viewer::SceneCache scene;
  scene.apply(*message);
  auto renderer = viewer::Renderer::create(settings);
  if (!renderer) {
    std::fprintf(stderr, "vrflow-viewer-snapshot: %s\n", renderer.error().message.c_str());
    return 1;
  }
  auto image = renderer->render(scene, viewer::Camera{});
  if (!image) {
    std::fprintf(stderr, "vrflow-viewer-snapshot: %s\n", image.error().message.c_str());
    return 1;
  }
  if (auto written = viewer::writePng(argv[1], *image); !written) {
    std::fprintf(stderr, "vrflow-viewer-snapshot: %s\n", written.error().message.c_str());
    return 1;
  }
  return 0;
}
