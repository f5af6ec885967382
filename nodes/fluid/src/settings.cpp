#include "vrflow/fluid/settings.hpp"

#include <cmath>
#include <string>

namespace vrflow::fluid {
namespace {

bool finite3(const msg::Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace

bool parsePreconditioner(const std::string& name, FluidPreconditioner& out) {
  if (name == "mic0") {
    out = FluidPreconditioner::kMic0;
  } else if (name == "multigrid") {
    out = FluidPreconditioner::kMultigrid;
  } else {
    return false;
  }
  return true;
}

const char* preconditionerName(FluidPreconditioner preconditioner) {
  return preconditioner == FluidPreconditioner::kMic0 ? "mic0" : "multigrid";
}

Status validateSettings(const FluidSettings& s) {
  const char* names[3] = {"nx", "ny", "nz"};
  const int n[3] = {s.nx, s.ny, s.nz};
  for (int a = 0; a < 3; ++a) {
    if (n[a] < 2 || n[a] > 1024) {
      return makeError(std::string("fluid: grid size ") + names[a] + " = " + std::to_string(n[a]) +
                       " must be between 2 and 1024 cells");
    }
  }
  if (!std::isfinite(s.cellSize) || s.cellSize <= 0.0) {
    return makeError("fluid: cell size " + std::to_string(s.cellSize) +
                     " must be a finite positive length in metres");
  }
  if (!finite3(s.origin)) return makeError("fluid: grid origin must be finite");
  if (!std::isfinite(s.density) || s.density <= 0.0) {
    return makeError("fluid: density " + std::to_string(s.density) + " must be positive (kg/m^3)");
  }
  if (!finite3(s.gravity)) return makeError("fluid: gravity must be finite");
  if (!std::isfinite(s.flipRatio) || s.flipRatio < 0.0 || s.flipRatio > 1.0) {
    return makeError("fluid: flip ratio " + std::to_string(s.flipRatio) +
                     " must be in [0, 1] (1 = FLIP, 0 = PIC)");
  }
  if (s.particlesPerCell != 1 && s.particlesPerCell != 8 && s.particlesPerCell != 27) {
    return makeError("fluid: particles per cell " + std::to_string(s.particlesPerCell) +
                     " must be 1, 8 or 27 (1, 2 or 3 per axis)");
  }
  if (s.maxParticles <= 0 || s.maxParticles > 50'000'000) {
    return makeError("fluid: max particles " + std::to_string(s.maxParticles) +
                     " must be in [1, 50000000]");
  }
  if (s.threads < 1 || s.threads > 64) {
    return makeError("fluid: threads " + std::to_string(s.threads) + " must be in [1, 64]");
  }
  if (!std::isfinite(s.cgTolerance) || s.cgTolerance <= 0.0 || s.cgTolerance >= 1.0) {
    return makeError("fluid: CG tolerance " + std::to_string(s.cgTolerance) +
                     " must be in (0, 1) (relative residual)");
  }
  if (!std::isfinite(s.volumeCorrection) || s.volumeCorrection < 0.0 || s.volumeCorrection > 1.0) {
    return makeError("fluid: volume correction " + std::to_string(s.volumeCorrection) +
                     " must be in [0, 1] (fraction of the density error removed per step)");
  }
  if (s.preconditioner != FluidPreconditioner::kMic0 &&
      s.preconditioner != FluidPreconditioner::kMultigrid) {
    return makeError("fluid: preconditioner " + std::to_string(static_cast<int>(s.preconditioner)) +
                     " is neither mic0 nor multigrid");
  }
  if (s.cgMaxIterations < 1) {
    return makeError("fluid: CG iteration cap must be at least 1");
  }
  return {};
}

Status validateTimeStep(const FluidSettings& s, double dt) {
  if (!std::isfinite(dt) || dt <= 0.0) {
    return makeError("fluid: time step " + std::to_string(dt) + " s must be finite and positive");
  }
  if (dt > 1.0) {
    return makeError("fluid: time step " + std::to_string(dt) + " s is absurd (more than 1 s)");
  }
  const double g = std::sqrt(s.gravity[0] * s.gravity[0] + s.gravity[1] * s.gravity[1] +
                             s.gravity[2] * s.gravity[2]);
  const double cells = g * dt * dt / s.cellSize;
  if (cells > kMaxGravityCellsPerStep) {
    const double limit = std::sqrt(kMaxGravityCellsPerStep * s.cellSize / g);
    return makeError("fluid: time step " + std::to_string(dt) + " s is absurd for " +
                     std::to_string(s.cellSize) + " m cells: gravity alone would move the liquid " +
                     std::to_string(cells) + " cells per step; use at most " +
                     std::to_string(limit) + " s");
  }
  return {};
}

}  // namespace vrflow::fluid
