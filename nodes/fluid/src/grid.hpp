#pragma once

#include <cstddef>
#include <vector>

// The staggered grid's storage: cell-centred scalars, and the three face-velocity components
// (u on x-faces: (nx+1) x ny x nz, v on y-faces, w on z-faces), all x-fastest.

// The passes that take most of a step are compiled twice on x86-64 with GCC: for the baseline
// and for x86-64-v3 (AVX2, FMA), picked when the program loads (an ifunc). Results then differ
// between machines with and without AVX2 in the last bits (fused multiply-adds), never between
// the blocks and the serial solver of one machine. VRFLOW_FLUID_BASELINE_ONLY builds the baseline
// alone (the tests run the solver's physics tests on it too).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(VRFLOW_FLUID_BASELINE_ONLY)
#define VRFLOW_FLUID_HOT __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define VRFLOW_FLUID_HOT
#endif

namespace vrflow::fluid::detail {

/// Four doubles processed together: one AVX register in the x86-64-v3 clones of the hot loops,
/// two SSE2 registers in the baseline ones (GCC and Clang vector extension). Loaded and stored
/// with memcpy in place: a function returning a Quad would change the ABI without AVX.
typedef double Quad __attribute__((vector_size(32)));

[[gnu::always_inline]] inline void load(Quad& v, const double* p) {
  __builtin_memcpy(&v, p, sizeof v);
}
[[gnu::always_inline]] inline void store(double* p, const Quad& v) {
  __builtin_memcpy(p, &v, sizeof v);
}

/// What a cell holds this step.
/// kSolid: inside a kinematic body, a moving wall (no pressure unknown, its faces keep the
/// body's velocity).
enum CellKind : unsigned char { kAir = 0, kLiquid = 1, kBody = 2, kSolid = 3 };

struct Grid {
  int nx = 0, ny = 0, nz = 0;
  double h = 1.0;
  double ox = 0, oy = 0, oz = 0;

  std::size_t cells() const { return static_cast<std::size_t>(nx) * ny * nz; }
  std::size_t cell(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * ny + j) * nx + i;
  }
  /// Faces of component `axis`: dims are (nx+1, ny, nz), (nx, ny+1, nz), (nx, ny, nz+1).
  int fdim(int axis, int d) const {
    const int n[3] = {nx, ny, nz};
    return n[d] + (axis == d ? 1 : 0);
  }
  std::size_t faces(int axis) const {
    return static_cast<std::size_t>(fdim(axis, 0)) * fdim(axis, 1) * fdim(axis, 2);
  }
  std::size_t face(int axis, int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * fdim(axis, 1) + j) * fdim(axis, 0) + i;
  }
};

}  // namespace vrflow::fluid::detail
