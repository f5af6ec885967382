#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vrflow/viewer/scene_cache.hpp"

// Dynamic meshes drawn smooth: a fluid's surface as water (a water colour, a specular highlight
// from the key light, slightly transparent) and a captured user's hull (opaque, a skin colour).

namespace vrflow::viewer {

/// The water's colour (linear RGB) and opacity.
inline constexpr std::array<float, 4> kWaterColour{0.16f, 0.46f, 0.78f, 0.82f};

/// The surface's vertices with smooth normals: each vertex's normal is the area-weighted sum of
/// its triangles' normals. Triangles naming a vertex that does not exist are left out.
DrawMesh waterMesh(const std::vector<float>& xyz, const std::vector<std::uint32_t>& indices);

/// A captured user's colour (opaque).
inline constexpr std::array<float, 4> kUserColour{0.86f, 0.64f, 0.52f, 1.0f};

/// Draws mesh resource `meshId` of `scene`, if it has arrived with triangles, with smooth normals:
/// in the shadow pass flat in the current colour (the caller's shadow state), else lit in
/// `colour` with a highlight, blended over what lies behind when its alpha is below 1.
void drawSmoothMesh(const SceneCache& scene, std::uint64_t meshId, bool shadowPass,
                    const std::array<float, 4>& colour);

/// A fluid's surface as water.
inline void drawWater(const SceneCache& scene, std::uint64_t surfaceId, bool shadowPass) {
  drawSmoothMesh(scene, surfaceId, shadowPass, kWaterColour);
}

}  // namespace vrflow::viewer
