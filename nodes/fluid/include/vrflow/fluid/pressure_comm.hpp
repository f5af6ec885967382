#pragma once

#include <vector>

// How the pressure solve talks to the other blocks of a distributed run. The grid is cut into
// slabs of whole z-planes, one per block; the conjugate gradient exchanges one plane with each
// neighbour per matrix product and sums dot products over the blocks. The serial solver has no
// PressureComm; vrflow::fluid_mpi provides one over MPI.

namespace vrflow::fluid {

/// One block's view of a distributed pressure solve.
class PressureComm {
 public:
  virtual ~PressureComm() = default;
  /// This block's index and the number of blocks.
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// The sum of `value` over every block (same result, same bits, on every block).
  virtual double sum(double value) = 0;
  /// Sends this block's first and last planes (`planeSize` values each, at k0 and k1 - 1) to
  /// its neighbours and receives theirs into planes k0 - 1 and k1 of `field` (a full grid).
  virtual void exchangeHalo(std::vector<double>& field, int planeSize, int k0, int k1) = 0;
  /// Gives every block the whole `field`: block b owns planes [kStart[b], kStart[b + 1]).
  virtual void allGather(std::vector<double>& field, int planeSize,
                         const std::vector<int>& kStart) = 0;
};

/// The planes [k0, k1) that block `rank` of `size` owns in a grid of `nz` planes.
inline void slabOf(int nz, int rank, int size, int& k0, int& k1) {
  k0 = static_cast<int>(static_cast<long long>(nz) * rank / size);
  k1 = static_cast<int>(static_cast<long long>(nz) * (rank + 1) / size);
}

}  // namespace vrflow::fluid
