#pragma once

#include <mpi.h>

#include "vrflow/fluid/block_comm.hpp"

// BlockComm over MPI: one block per rank of `comm`, neighbours rank - 1 and rank + 1 along z.
// Scalar and vector sums gather every rank's value and add them in rank order, so every rank
// gets the same bits whatever the MPI reduction algorithm.

namespace vrflow::fluid {

class MpiBlockComm final : public BlockComm {
 public:
  /// Uses `comm` (not owned; MPI must be initialised).
  explicit MpiBlockComm(MPI_Comm comm);
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  double sum(double value) override;
  double max(double value) override;
  void sum(std::vector<double>& values) override;
  void max(std::vector<double>& values) override;
  void exchangeHalo(std::vector<double>& field, int planeSize, int planeCount, int k0, int k1,
                    int depth) override;
  void addHalo(std::vector<double>& field, int planeSize, int planeCount, int k0, int k1) override;
  std::vector<double> exchange(const std::vector<std::vector<double>>& outgoing,
                               int stride) override;
  std::vector<float> gatherToRoot(const std::vector<float>& values) override;

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
  std::vector<double> buffer_;
};

}  // namespace vrflow::fluid
