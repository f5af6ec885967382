#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/viewer/camera.hpp"
#include "vrflow/viewer/image.hpp"
#include "vrflow/viewer/scene_cache.hpp"
#include "vrflow/viewer/view_volume.hpp"
#include "vrflow/viewer/window.hpp"

// Draws a SceneCache with OpenGL 1.x through OSMesa (Mesa's software rasteriser, no display) or
// into an on-screen Window: the same drawing code in either context.

namespace vrflow::viewer {

/// How a frame looks. Colours are linear 0..1 RGB.
struct RenderSettings {
  int width = 960;  ///< the image (of the tile, for a wall)
  int height = 540;
  Tile tile;  ///< the part of the view drawn: the whole view is tile.cols*width x tile.rows*height
  std::array<float, 3> background{0.80f, 0.86f, 0.93f};  ///< where nothing is drawn
  bool ground = true;                                    ///< a checkered plane y = groundHeight
  double groundHeight = 0.0;
  double groundHalfSize = 20.0;  ///< the plane spans +-this along x and z
  double groundTile = 1.0;       ///< checker square size
  std::array<float, 3> groundLight{0.78f, 0.78f, 0.76f};
  std::array<float, 3> groundDark{0.62f, 0.62f, 0.60f};
  bool shadows = true;   ///< dark footprints under objects
  bool netLines = true;  ///< a net's triangle edges drawn darker
  int supersample = 1;   ///< 1..4: draws at this many times the size, then averages (antialiasing)
  double pointRadius = 0.08;  ///< spheres drawn for `point` objects
  float particleSize = 3.0f;  ///< fluid particles, pixels
  std::array<float, 3> particleColour{0.15f, 0.40f, 0.85f};
  /// Edge blending of a wall tile (wall.hpp's blendMask): width x height bytes, rows from the
  /// top, the frame multiplied by mask / 255; empty: none.
  std::vector<std::uint8_t> blendMask;
};

/// The fixed lights: white, directional (world directions towards the lights), no specular. A lit
/// surface of base colour c and unit normal n shows c * (ambient + key * max(0, n.k) + fill *
/// max(0, n.f)), k and f the normalised directions; both sides of a surface are lit.
struct Lighting {
  float ambient = 0.30f;
  float key = 0.72f;
  float fill = 0.22f;
  std::array<float, 3> keyDirection{0.45f, 1.0f, 0.55f};     ///< from above, front right
  std::array<float, 3> fillDirection{-0.6f, 0.35f, -0.45f};  ///< from behind left
};
/// The lighting every frame uses.
inline constexpr Lighting kLighting{};

/// The base colour of object `id`: a hue picked by hashing the id, so the same id always gets
/// the same colour, and neighbouring ids different ones.
std::array<float, 3> objectColour(std::uint64_t id);

/// An OSMesa context with its colour and depth buffers, or a window's context. One per thread
/// at a time.
class Renderer {
 public:
  /// Creates the context (RGBA, 24-bit depth, 8-bit stencil) for settings.width x height.
  static Result<Renderer> create(const RenderSettings& settings);
  /// Draws into `window`'s back buffer (its size must be settings.width x height, supersample
  /// 1); render() reads the pixels back before any swap, and the caller swaps. The window must
  /// outlive the renderer.
  static Result<Renderer> create(const RenderSettings& settings, Window& window);
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  ~Renderer();

  /// Renders the scene seen by `camera`; the image is settings.width x settings.height. With
  /// `within`, only the objects whose bounds meet that box are drawn (and those without bounds):
  /// a routed viewer draws what its volume of interest holds, not objects the route stopped
  /// updating.
  Result<Image> render(const SceneCache& scene, const Camera& camera,
                       const msg::Aabb* within = nullptr);
  /// The same through an explicit `frustum` (a wall tile's head-coupled one) instead of the
  /// settings' tile of the camera's view; `camera` gives the eye and the view's orientation.
  Result<Image> render(const SceneCache& scene, const Camera& camera, const Frustum& frustum,
                       const msg::Aabb* within = nullptr);
  const RenderSettings& settings() const;
  /// The OpenGL renderer and version strings ("llvmpipe (LLVM 15, 256 bits), 4.5 ..."), for logs.
  const std::string& description() const;

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow::viewer
