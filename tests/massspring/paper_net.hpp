#pragma once

// The paper scene's net as examples/paper_scene/paper_scene.xml generates it, for the tests.

#include "vrflow/massspring/net.hpp"

namespace vrflow::massspring {

/// 20 x 20 nodes 0.1 m apart, 8 kg (20 g nodes), 300 N/m (shear 150, bend 30), damping 0.2,
/// maximum stretch 1.1, corners pinned, centred on the origin.
inline GridParams paperSceneNet() {
  GridParams grid;
  grid.n = grid.m = 20;
  grid.spacing = 0.1;
  grid.mass = 8.0;
  grid.stiffness = 300.0;
  grid.damping = 0.2;
  grid.maxStretch = 1.1;
  return grid;
}

}  // namespace vrflow::massspring
