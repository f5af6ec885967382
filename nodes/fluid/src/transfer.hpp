#pragma once

#include <algorithm>
#include <cstddef>

#include "grid.hpp"

// Trilinear stencils between particles and the staggered grid, written for the particle loops:
// one locate() per point gives, per dimension, the clamped cell coordinate and fraction on the
// face lattice (the component along that dimension) and on the centre lattice (the two others);
// the three components' stencils share them.

namespace vrflow::fluid::detail {

/// The grid's geometry as the particle loops use it (strides per velocity component).
struct Lattice {
  double origin[3] = {0, 0, 0};
  double invH = 1.0;
  int n[3] = {0, 0, 0};
  std::size_t sy[3] = {0, 0, 0};  ///< stride of j in component a's face array
  std::size_t sz[3] = {0, 0, 0};  ///< stride of k

  explicit Lattice(const Grid& g) {
    origin[0] = g.ox;
    origin[1] = g.oy;
    origin[2] = g.oz;
    invH = 1.0 / g.h;
    n[0] = g.nx;
    n[1] = g.ny;
    n[2] = g.nz;
    for (int a = 0; a < 3; ++a) {
      sy[a] = static_cast<std::size_t>(g.fdim(a, 0));
      sz[a] = sy[a] * static_cast<std::size_t>(g.fdim(a, 1));
    }
  }
};

/// Where a point falls: per dimension, base index and fraction on both lattices.
struct Located {
  int faceBase[3], centreBase[3];
  double faceFrac[3], centreFrac[3];
};

// One dimension of locate(): g is the point's coordinate in cells; n the cell count.
[[gnu::always_inline]] inline void locateAxis(double g, int n, int& faceBase, double& faceFrac,
                                              int& centreBase, double& centreFrac) {
  // min/max rather than branches: the same values as std::clamp for finite coordinates.
  const double hiFace = static_cast<double>(n), hiCentre = static_cast<double>(n - 1);
  const double vf = std::min(std::max(g, 0.0), hiFace);
  int bf = static_cast<int>(vf);
  bf = bf >= n ? n - 1 : bf;
  faceBase = bf;
  faceFrac = vf - bf;
  const double vc = std::min(std::max(g - 0.5, 0.0), hiCentre);
  int bc = static_cast<int>(vc);
  bc = bc >= n - 1 ? n - 2 : bc;
  centreBase = bc;
  centreFrac = vc - bc;
}

[[gnu::always_inline]] inline void locate(const Lattice& l, const double* x, Located& c) {
  locateAxis((x[0] - l.origin[0]) * l.invH, l.n[0], c.faceBase[0], c.faceFrac[0], c.centreBase[0],
             c.centreFrac[0]);
  locateAxis((x[1] - l.origin[1]) * l.invH, l.n[1], c.faceBase[1], c.faceFrac[1], c.centreBase[1],
             c.centreFrac[1]);
  locateAxis((x[2] - l.origin[2]) * l.invH, l.n[2], c.faceBase[2], c.faceFrac[2], c.centreBase[2],
             c.centreFrac[2]);
}

/// Component a's stencil: first face index and the three fractions.
struct Stencil {
  std::size_t base, sy, sz;
  double fx, fy, fz;
};

inline Stencil stencilOf(const Lattice& l, int a, const Located& c) {
  const int bx = a == 0 ? c.faceBase[0] : c.centreBase[0];
  const int by = a == 1 ? c.faceBase[1] : c.centreBase[1];
  const int bz = a == 2 ? c.faceBase[2] : c.centreBase[2];
  Stencil s;
  s.sy = l.sy[a];
  s.sz = l.sz[a];
  s.base = static_cast<std::size_t>(bz) * s.sz + static_cast<std::size_t>(by) * s.sy +
           static_cast<std::size_t>(bx);
  s.fx = a == 0 ? c.faceFrac[0] : c.centreFrac[0];
  s.fy = a == 1 ? c.faceFrac[1] : c.centreFrac[1];
  s.fz = a == 2 ? c.faceFrac[2] : c.centreFrac[2];
  return s;
}

/// Trilinear interpolation of a face field (x, then y, then z).
inline double gather(const double* field, const Stencil& s) {
  const double fx = s.fx, fy = s.fy, fz = s.fz;
  const double* p = field + s.base;
  const double c00 = p[0] + fx * (p[1] - p[0]);
  const double c10 = p[s.sy] + fx * (p[s.sy + 1] - p[s.sy]);
  const double c01 = p[s.sz] + fx * (p[s.sz + 1] - p[s.sz]);
  const double c11 = p[s.sz + s.sy] + fx * (p[s.sz + s.sy + 1] - p[s.sz + s.sy]);
  const double c0 = c00 + fy * (c10 - c00);
  const double c1 = c01 + fy * (c11 - c01);
  return c0 + fz * (c1 - c0);
}

/// Two doubles processed together (SSE2, the x86-64 baseline; GCC and Clang vector extension).
typedef double Pair __attribute__((vector_size(16)));

inline Pair loadPair(const double* p) {
  Pair v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

/// gather() of two interleaved fields at once (`pairs` holds two values per face). A face and
/// its x neighbour are one load of four values, so the eight corners are four loads: z, then y,
/// then x.
inline Pair gatherPair(const double* pairs, const Stencil& s) {
  const double* p = pairs + 2 * s.base;
  const std::size_t y = 2 * s.sy, z = 2 * s.sz;
  const Quad fy = {s.fy, s.fy, s.fy, s.fy}, fz = {s.fz, s.fz, s.fz, s.fz};
  Quad r00, r10, r01, r11;
  load(r00, p);
  load(r10, p + y);
  load(r01, p + z);
  load(r11, p + z + y);
  const Quad c0 = r00 + fz * (r01 - r00);
  const Quad c1 = r10 + fz * (r11 - r10);
  const Quad c = c0 + fy * (c1 - c0);  // the pair at x, then at x + 1
  const Pair lo = {c[0], c[1]}, hi = {c[2], c[3]};
  return lo + Pair{s.fx, s.fx} * (hi - lo);
}

/// Adds a particle's velocity component `va` and its weights to `acc`, which holds (sum of
/// weighted velocities, sum of weights) per face, interleaved so both share a cache line: a face
/// and its x neighbour are one read-modify-write of four values.
/// Only the rows of planes z + dk in [0, span] are added (z: the stencil's first plane, relative
/// to the first plane to add).
inline void splat(double* acc, const Stencil& s, double va, int z, int span) {
  const Quad x = Quad{1 - s.fx, 1 - s.fx, s.fx, s.fx} * Quad{va, 1.0, va, 1.0};
  for (int dk = 0; dk < 2; ++dk) {
    if (static_cast<unsigned>(z + dk) > static_cast<unsigned>(span)) continue;
    const double wz = dk ? s.fz : 1 - s.fz;
    for (int dj = 0; dj < 2; ++dj) {
      const double wyz = wz * (dj ? s.fy : 1 - s.fy);
      double* row = acc + 2 * (s.base + static_cast<std::size_t>(dk) * s.sz +
                               static_cast<std::size_t>(dj) * s.sy);
      Quad sum;
      load(sum, row);
      sum += Quad{wyz, wyz, wyz, wyz} * x;
      store(row, sum);
    }
  }
}

}  // namespace vrflow::fluid::detail
