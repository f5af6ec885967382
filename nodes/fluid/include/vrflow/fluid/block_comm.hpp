#pragma once

#include <vector>

// How a block of a distributed fluid talks to the others. The grid is cut into slabs of whole
// z-planes, one per block (an MPI rank); every block keeps full-size arrays but computes only its
// own planes, and exchanges the planes next to its slab with its neighbours. Particles belong to
// the block whose slab holds them and move between blocks after advection. The serial solver has
// no BlockComm; vrflow::fluid_mpi provides one over MPI.

namespace vrflow::fluid {

/// One block's link to the other blocks of a distributed run. Every call is collective: every
/// block makes the same calls in the same order.
class BlockComm {
 public:
  virtual ~BlockComm() = default;
  /// This block's index and the number of blocks.
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// Sum and maximum of `value` over every block (the same bits on every block).
  virtual double sum(double value) = 0;
  virtual double max(double value) = 0;
  /// Element-wise sum of `values` over every block, in place.
  virtual void sum(std::vector<double>& values) = 0;
  /// Element-wise maximum of `values` over every block, in place.
  virtual void max(std::vector<double>& values) = 0;
  /// Fills the `depth` planes on each side of this block's planes [k0, k1) of `field` (planes of
  /// `planeSize` values, `planeCount` planes) with the neighbours' values.
  virtual void exchangeHalo(std::vector<double>& field, int planeSize, int planeCount, int k0,
                            int k1, int depth) = 0;
  /// The opposite: sends planes k0 - 1 and k1 (contributions this block made to its neighbours'
  /// planes) and adds what the neighbours made to planes k0 and k1 - 1.
  virtual void addHalo(std::vector<double>& field, int planeSize, int planeCount, int k0,
                       int k1) = 0;
  /// Sends outgoing[b] to block b (records of `stride` doubles) and returns what the others sent
  /// here, in block order.
  virtual std::vector<double> exchange(const std::vector<std::vector<double>>& outgoing,
                                       int stride) = 0;
  /// Concatenates every block's `values` in block order; the result is complete on block 0 only.
  virtual std::vector<float> gatherToRoot(const std::vector<float>& values) = 0;
};

/// The cell planes [k0, k1) that block `rank` of `size` owns in a grid of `nz` planes.
inline void slabOf(int nz, int rank, int size, int& k0, int& k1) {
  k0 = static_cast<int>(static_cast<long long>(nz) * rank / size);
  k1 = static_cast<int>(static_cast<long long>(nz) * (rank + 1) / size);
}

/// The block that owns cell plane k.
inline int blockOfPlane(int nz, int size, int k) {
  for (int r = 0; r < size; ++r) {
    int k0, k1;
    slabOf(nz, r, size, k0, k1);
    if (k < k1) return r;
  }
  return size - 1;
}

}  // namespace vrflow::fluid
