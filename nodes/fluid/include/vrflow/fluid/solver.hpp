#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/camera/user_surface.hpp"
#include "vrflow/fluid/settings.hpp"
#include "vrflow/message/shape.hpp"
#include "vrflow/message/values.hpp"

// A liquid on a staggered (MAC) grid with FLIP/PIC particles for the free surface, solid walls
// at the grid's faces, gravity, and two-way coupling with rigid bodies after Carlson, Mucha and
// Turk (2004), modified (as in Allard & Raffin 2006) to return forces instead of writing body
// velocities: bodies are rasterised into the grid, the pressure projection is solved everywhere
// with each body's cells carrying the body's density, and the momentum change inside each body
// (less gravity) is the force and torque the liquid applies to it.

namespace vrflow::fluid {

/// A rigid body as the fluid sees it at the start of a step (state from its animator).
struct RigidBody {
  std::uint64_t id = 0;  ///< object id, echoed in BodyForce
  msg::Shape shape;      ///< collision shape in the body frame (origin = centre of mass)
  msg::Vec3 position{};  ///< centre of mass, world
  msg::Quat orientation{0, 0, 0, 1};  ///< body to world, xyzw
  msg::Vec3 linearVelocity{};         ///< m/s
  msg::Vec3 angularVelocity{};        ///< rad/s, world frame
  double mass = 1.0;                  ///< kg; the body's density is mass / shape volume
  /// Moved by its animator whatever the liquid does (infinite mass, e.g. a ground or a captured
  /// user): it pushes the liquid with kKinematicDensityRatio times its density; mass is ignored
  /// and its force is meaningless.
  bool kinematic = false;
  /// A captured user (nodes/camera) in place of `shape`: a kinematic solid given by its distance
  /// field, whose surface moves with its velocity field. It must outlive the step.
  const camera::UserSurface* surface = nullptr;
};

/// Density of kinematic bodies in the projection, relative to the liquid's.
inline constexpr double kKinematicDensityRatio = 1000.0;

/// An independent point mass (a mass-spring node) as the fluid sees it: a small sphere.
struct PointMass {
  std::uint64_t id = 0;     ///< object id of the net
  std::uint32_t index = 0;  ///< node index in the net
  msg::Vec3 position{};
  msg::Vec3 velocity{};
  double mass = 0.01;
  double radius = 0.02;  ///< radius of the sphere rasterised for it
};

/// What the liquid did to one body over the step: apply `force` and `torque` (about the centre
/// of mass `point`) for `duration` seconds. Gravity is not included: the animator adds its own.
/// A body none of whose cells holds particles or shares a face with a liquid cell is in air
/// (p = 0 around it): its force and torque are zero, whatever bodies it touches.
struct BodyForce {
  std::uint64_t id = 0;
  std::uint32_t index = 0;  ///< node index for point masses, 0 for rigid bodies
  msg::Vec3 force{};
  msg::Vec3 torque{};
  msg::Vec3 point{};
  double duration = 0.0;
  int cells = 0;  ///< grid faces the body covered (0: too small or outside: no force)
  /// False when another block reports this body (blocks holding their own body lists,
  /// setLocalBodies): every block holding it computed the same force, the lowest one reports it.
  bool reported = true;
};

/// How far beyond its slab, in cells, a block with local bodies must hold the bodies (its
/// rasterisation reaches one plane beyond; the second is a margin).
inline constexpr int kLocalBodyMargin = 2;

/// Numbers about the last step, for tests and benchmarks.
struct StepStats {
  int cgIterations = 0;
  double cgResidual = 0.0;  ///< final |r| / |b| (0 when b = 0)
  bool cgConverged = true;
  int fluidCells = 0;              ///< cells holding liquid particles
  int bodyCells = 0;               ///< cells inside bodies that touch the liquid (unknowns)
  double maxSpeed = 0.0;           ///< largest face velocity magnitude after projection
  std::uint64_t bytesTouched = 0;  ///< estimate of this block's memory traffic in the pressure CG
  double pressureSeconds = 0.0;    ///< wall time of the pressure CG (for bandwidth estimates)
  double particleDensity = 1.0;    ///< mean particles per interior liquid cell / particlesPerCell
  double targetDivergence = 0.0;   ///< what volume control would ask at the mean density, 1/s
};

/// A distributed run's link between blocks (block_comm.hpp); the serial solver uses none.
class BlockComm;

/// The fluid simulation. Not thread-safe; owns no threads.
class FluidSolver {
 public:
  /// Builds a solver; the settings are validated (clear error on bad ones).
  static Result<std::unique_ptr<FluidSolver>> create(const FluidSettings& settings);
  ~FluidSolver();
  FluidSolver(const FluidSolver&) = delete;
  FluidSolver& operator=(const FluidSolver&) = delete;

  /// Fills the cells whose centres lie in `box` with liquid at rest (particlesPerCell each).
  Status addLiquidBox(const msg::Aabb& box);

  /// Advances by dt with the given bodies (their state at the start of the step) and returns
  /// the force each receives. Bodies with invalid shapes, masses or non-finite state give an
  /// error naming the body; nothing is changed then.
  Result<std::vector<BodyForce>> step(double dt, const std::vector<RigidBody>& bodies,
                                      const std::vector<PointMass>& points = {});

  /// Makes this solver one block of a distributed run: it owns the z-planes of its slab and the
  /// particles in them, and every step, addLiquidBox and query below becomes collective (every
  /// block calls it). Call before addLiquidBox; nullptr (the default) is the serial solver.
  Status setBlockComm(BlockComm* comm);

  /// With a block link: each block's step gets only the bodies and points near its slab (those
  /// whose bounds meet its planes widened by kLocalBodyMargin cells), so blocks hold different
  /// lists. Per-body sums are then combined by id over every block's list (the union, in id
  /// order), and each body's force is marked `reported` on the lowest block holding it. A block
  /// must hold every body that reaches its planes; the others it may hold or not.
  void setLocalBodies(bool local);

  const FluidSettings& settings() const;
  const StepStats& lastStats() const;
  /// This block's particle positions, xyz per particle (all of them in a serial run).
  const std::vector<float>& particlePositions() const;
  /// Every block's particle positions, in block order, complete on block 0 (collective).
  std::vector<float> gatherParticlePositions() const;
  /// Number of particles over every block (collective).
  std::size_t particleCount() const;
  /// Liquid volume estimated from the particles: their number over particlesPerCell times the
  /// relative particle density of interior liquid cells at the last step (StepStats), in cells,
  /// times the cell volume. Clumping reads as lost volume, drifting apart as gained volume
  /// (collective).
  double liquidVolume() const;
  /// Largest |velocity| sampled at the particles.
  double maxParticleSpeed() const;
  /// Highest particle y in the grid column holding (x, z).
  double surfaceHeightAt(double x, double z) const;
  /// Largest |divergence - target| of the face velocities over liquid cells after the last
  /// projection, in 1/s; the per-cell target is 0 unless volume control is on (see FluidSettings).
  double maxDivergence() const;
  /// World bounds of the grid.
  msg::Aabb bounds() const;

 private:
  struct Impl;
  explicit FluidSolver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrflow::fluid
