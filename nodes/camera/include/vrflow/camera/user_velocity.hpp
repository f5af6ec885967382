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
  /// Frames over which the change is averaged in time (exponentially, the newest frame weighing
  /// 1 / frames; needs the caller's history). A surface slower than a voxel per frame moves in
  /// voxel steps some frames apart: one frame's change reads a step as a voxel per frame (3 m/s
  /// for 3 cm at 100 Hz) and the frames between as still. 1: this frame's change only.
  int frames = 1;
};

/// What the time average (settings.frames > 1) keeps between frames: the averaged change of the
/// distance field (m per frame, one per cell). Empty: no average yet (it starts from zero).
using SurfaceChangeHistory = std::vector<float>;

/// The velocity (three floats per cell, x fastest, m/s) of the surface of `sdfNow` on `spec`'s
/// grid, from `sdfBefore` one step `dt` (s) earlier. Zero where the gradient vanishes (the
/// medial axis), beyond the band, and everywhere when either field has no surface. With
/// settings.frames > 1 and a `history`, the change is the time average that `history` carries
/// from the previous call (reset when a field has no surface or the grid's size changes).
std::vector<float> surfaceVelocity(const GridSpec& spec, const std::vector<float>& sdfBefore,
                                   const std::vector<float>& sdfNow, double dt,
                                   const SurfaceVelocitySettings& settings = {},
                                   SurfaceChangeHistory* history = nullptr);

}  // namespace vrflow::camera
