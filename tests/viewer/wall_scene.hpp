#pragma once

#include <cmath>
#include <vector>

#include "scene_messages.hpp"
#include "vrflow/viewer/camera.hpp"
#include "vrflow/viewer/image.hpp"

// The scene the wall tests draw (tiles, on-screen tiles, mosaics), and what an edge pixel is.

namespace vrflow::viewer::testing {

// A box, a sphere, a capsule and a sagging net with its edges drawn, over the ground with
// shadows: every kind of primitive crosses a tile border somewhere.
inline SceneCache wallScene() {
  SceneCache scene;
  feed(scene, [](msg::MessageBuilder& b) {
    addShape(b, 101, msg::Shape::box({0.5, 0.5, 0.5}));
    addShape(b, 102, msg::Shape::sphere(0.6));
    addShape(b, 103, msg::Shape::capsule(0.3, 0.5));
    addRigid(b, 1, {-0.4, 0.5, 0.2}, 101, {0, std::sin(0.3), 0, std::cos(0.3)});
    addRigid(b, 2, {0.3, 1.2, -1.0}, 102);
    addRigid(b, 3, {1.6, 0.9, 0.4}, 103, {0, 0, std::sin(0.4), std::cos(0.4)});
    std::vector<double> xyz;
    std::vector<std::uint32_t> triangles;
    const int n = 12;
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double x = -1.5 + 3.0 * i / (n - 1), z = -1.5 + 3.0 * j / (n - 1);
        xyz.insert(xyz.end(), {x, 1.8 - 0.3 * (1.0 - (x * x + z * z) / 4.5), z});
      }
    }
    for (std::uint32_t j = 0; j + 1 < n; ++j) {
      for (std::uint32_t i = 0; i + 1 < n; ++i) {
        const std::uint32_t a = j * n + i;
        triangles.insert(triangles.end(), {a, a + 1, a + n, a + 1, a + n + 1, a + n});
      }
    }
    addNet(b, 7, xyz, triangles);
  });
  return scene;
}

inline Camera wallCamera() {
  Camera camera;
  camera.eye = {1.0, 3.0, 6.5};
  camera.target = {0.1, 0.8, 0.0};
  return camera;
}

/// True when a neighbour of pixel (x, y) has another colour: an edge, where rounding may differ.
inline bool onAnEdge(const Image& image, int x, int y) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= image.width || v >= image.height) continue;
      if (image.at(u, v) != image.at(x, y)) return true;
    }
  }
  return false;
}

}  // namespace vrflow::viewer::testing
