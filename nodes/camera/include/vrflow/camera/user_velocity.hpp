#pragma once
// The velocity of the user's surface from two consecutive distance fields. A distance field
// moved with its surface satisfies the level-set equation d(phi)/dt + v . grad(phi) = 0, so the
// change of phi at a fixed point gives the surface's speed along the normal:
//   v = -(phi_now - phi_before) / dt * grad(phi_now) / |grad(phi_now)|^2.
// Only this normal component can be seen in a shape without texture (the aperture problem: a
// sphere spinning in place looks still); it is the component that contact and the fluid's
// boundary need, and the tangential one is left zero. The voxel distance field changes by whole
// voxel steps, so the change is averaged over a box of (2 smoothing + 1)^3 cells first.

#include <vector>

#include "vrflow/camera/voxel_grid.hpp"

namespace vrflow::camera {

/// How the surface velocity is estimated.
struct SurfaceVelocitySettings {
  int smoothing = 1;     ///< radius (cells) of the box average of the distance change; 0: none
  double band = 0.1;     ///< only cells within this distance (m) of the surface get a velocity
  double maxSpeed = 20;  ///< speeds are clamped to this (m/s)
};

/// The velocity (three floats per cell, x fastest, m/s) of the surface of `sdfNow` on `spec`'s
/// grid, from `sdfBefore` one step `dt` (s) earlier. Zero where the gradient vanishes (the
/// medial axis), beyond the band, and everywhere when either field has no surface.
std::vector<float> surfaceVelocity(const GridSpec& spec, const std::vector<float>& sdfBefore,
                                   const std::vector<float>& sdfNow, double dt,
                                   const SurfaceVelocitySettings& settings = {});

}  // namespace vrflow::camera
