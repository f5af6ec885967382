#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vrflow/viewer/scene_cache.hpp"

// A fluid's surface mesh drawn as water: smooth (area-weighted) normals, a water colour, a
// specular highlight from the key light, slightly transparent.

namespace vrflow::viewer {

/// The water's colour (linear RGB) and opacity.
inline constexpr std::array<float, 4> kWaterColour{0.16f, 0.46f, 0.78f, 0.82f};

/// The surface's vertices with smooth normals: each vertex's normal is the area-weighted sum of
/// its triangles' normals. Triangles naming a vertex that does not exist are left out.
DrawMesh waterMesh(const std::vector<float>& xyz, const std::vector<std::uint32_t>& indices);

/// Draws the surface of resource `surfaceId` of `scene`, if it has arrived with triangles; in the
/// shadow pass flat in the current colour (the caller's shadow state), else as lit water.
void drawWater(const SceneCache& scene, std::uint64_t surfaceId, bool shadowPass);

}  // namespace vrflow::viewer
