#pragma once

#include <vector>

#include "grid.hpp"
#include "vrflow/fluid/solver.hpp"

// The liquid's force on a net's node (a PointMass), computed per node from the fields sampled
// at its centre (issue 26): buoyancy of the part of its sphere below the liquid's level, drag
// against the liquid's velocity there (implicit for the node's own mass), and the reaction on
// the liquid in the cells around the node. Nodes are not rasterised into the grid: a node of
// any size gets its force, and the projection never treats a 20 g node as a light blob of
// liquid.

namespace vrflow::fluid::detail {

/// Drag coefficient of a sphere at the Reynolds numbers of a net in water (about 1e4 to 1e5).
inline constexpr double kSphereDragCoefficient = 0.47;

/// Values gathered around one node, per slot: the liquid's level in the 4 columns around it (x
/// by z, each from the block holding the column), then per axis 8 faces around it: (velocity,
/// 1) for a face next to a liquid cell, (0, 0) otherwise. Blocks add their slots (a slot a
/// block does not hold stays 0), so every block ends with the serial values, bit for bit.
inline constexpr int kNodeColumns = 4;
inline constexpr int kNodeFaces = 8;
inline constexpr int kNodeSlots = kNodeColumns + 3 * 2 * kNodeFaces;

/// What a block knows of the grid for the gathering.
struct NodeGridView {
  const Grid* grid = nullptr;
  int k0 = 0, k1 = 0;  ///< the block's cell planes
  int kEnd[3] = {0, 0, 0};
  const std::vector<unsigned char>* kind = nullptr;  ///< read one plane beyond the slab
  const std::vector<int>* particlesInCell = nullptr;
  int particlesPerCell = 8;
  const std::vector<double>* u = nullptr;  ///< the three face components
};

/// Whether the node's centre lies in the grid (a node outside gets no force).
bool nodeInGrid(const Grid& grid, const PointMass& node);
/// Adds this block's slots for the node to `slots` (kNodeSlots values).
void gatherNodeSlots(const NodeGridView& view, const PointMass& node, double* slots);
/// The liquid's level (y) at the node from the combined slots.
double nodeLiquidLevel(const Grid& grid, const PointMass& node, const double* slots);
/// Volume of the part of a sphere of radius r whose centre is at height y below the level.
double submergedVolume(double r, double y, double level);
/// The force on the node over dt from the combined slots: buoyancy -rho V_sub g, and per axis the
/// drag 0.5 rho C_d A |v - u| (A the submerged part's frontal area across that axis) made
/// implicit for the node's mass (k / (1 + k dt / m)),
/// so that it never reverses the node's velocity relative to the liquid in one step. `cells` is
/// the number of faces next to liquid around the node, at least 1 for a node in the grid.
BodyForce nodeForce(const Grid& grid, const PointMass& node, const double* slots,
                    double liquidDensity, const msg::Vec3& gravity, double dt);
/// Takes the node's force from the liquid: -force dt spread over the faces next to liquid
/// around the node (the gathering's weights, renormalised), on this block's faces.
void applyNodeReaction(const NodeGridView& view, const PointMass& node, const double* slots,
                       const BodyForce& force, double liquidDensity, double dt,
                       std::vector<double>* u);

}  // namespace vrflow::fluid::detail
