#pragma once

#include <cstdint>
#include <string>

#include "vrflow/base/result.hpp"
#include "vrflow/message/values.hpp"

// What a fluid simulation is made of: the grid, the liquid's material and the solver's knobs.
// Every value is checked by validateSettings() before a solver is built from it.

namespace vrflow::fluid {

/// The pressure CG's preconditioner.
enum class FluidPreconditioner {
  kMic0,       ///< modified incomplete Cholesky: sweeps in cell order, one thread
  kMultigrid,  ///< one multigrid V-cycle: fewer iterations, every pass on the solver's threads
};

/// Grid, material and solver settings, with the paper's scene as defaults (32 x 64 x 32 cells).
struct FluidSettings {
  int nx = 32;                         ///< cells along x
  int ny = 64;                         ///< cells along y (up, gravity is -y by default)
  int nz = 32;                         ///< cells along z
  double cellSize = 1.0 / 32.0;        ///< edge of a cubic cell, metres
  msg::Vec3 origin{0.0, 0.0, 0.0};     ///< world position of the grid's min corner
  double density = 1000.0;             ///< liquid density, kg/m^3
  msg::Vec3 gravity{0.0, -9.81, 0.0};  ///< m/s^2
  double flipRatio = 0.95;             ///< 1 = pure FLIP, 0 = pure PIC
  int particlesPerCell = 8;            ///< seeding density (2 x 2 x 2 jittered)
  int maxParticles = 200000;           ///< seeding stops with an error beyond this
  double cgTolerance = 1e-6;           ///< pressure solve: stop when |r| <= tol * |b| (2-norm)
  int cgMaxIterations = 1000;          ///< pressure solve: iteration cap
  /// Pressure solve: the CG's preconditioner (the result agrees to the CG tolerance, not to
  /// the bit, between the two). MIC(0) by default: on the paper scene's 32 x 64 x 32 grid it
  /// is faster than multigrid on an idle 2-core machine; multigrid pays from 64 x 128 x 64 in
  /// one block.
  FluidPreconditioner preconditioner = FluidPreconditioner::kMic0;
  /// Volume control (after Kim et al. 2007, per cell): FLIP particles drift apart or clump, so
  /// each step asks every liquid cell not next to air for a divergence of
  /// -volumeCorrection * (1 - n / n0) / dt, n its particle count, n0 = particlesPerCell.
  /// 0 turns it off.
  double volumeCorrection = 0.1;
  std::uint64_t seed = 1;  ///< particle jitter seed (results are deterministic)
  /// Threads of this solver (of each block) for its particle loops and grid passes, 1 to 64.
  /// The results are the same bits whatever the count.
  int threads = 1;
};

/// Largest time step accepted: a step over which gravity alone would move liquid more than
/// this many cells is absurd for the solver (CFL far beyond what particles can follow).
inline constexpr double kMaxGravityCellsPerStep = 5.0;

/// The preconditioner named `name` ("mic0" or "multigrid"); false for any other name.
bool parsePreconditioner(const std::string& name, FluidPreconditioner& out);

/// The name of a preconditioner, as parsePreconditioner() reads it.
const char* preconditionerName(FluidPreconditioner preconditioner);

/// Checks sizes (positive, at most 1024 cells per axis), finite values, ratios in range.
Status validateSettings(const FluidSettings& settings);

/// Checks a time step against the settings: finite, positive and not absurd (see above).
Status validateTimeStep(const FluidSettings& settings, double dt);

}  // namespace vrflow::fluid
