#include "vrflow/fluid/mpi_block_comm.hpp"

#include <algorithm>
#include <cstddef>

namespace vrflow::fluid {
namespace {
constexpr int kTagUp = 11;
constexpr int kTagDown = 12;
}  // namespace

MpiBlockComm::MpiBlockComm(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

double MpiBlockComm::sum(double value) {
  std::vector<double> all(static_cast<std::size_t>(size_));
  MPI_Allgather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, comm_);
  double total = 0.0;
  for (const double v : all) total += v;
  return total;
}

double MpiBlockComm::max(double value) {
  double out = value;
  MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return out;
}

void MpiBlockComm::sum(std::vector<double>& values) {
  const int n = static_cast<int>(values.size());
  std::vector<double> all(values.size() * static_cast<std::size_t>(size_));
  MPI_Allgather(values.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, comm_);
  for (std::size_t i = 0; i < values.size(); ++i) {
    double total = 0.0;
    for (int r = 0; r < size_; ++r) total += all[static_cast<std::size_t>(r) * values.size() + i];
    values[i] = total;
  }
}

void MpiBlockComm::max(std::vector<double>& values) {
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MAX,
                comm_);
}

void MpiBlockComm::exchangeHalo(std::vector<double>& field, int planeSize, int planeCount, int k0,
                                int k1, int depth) {
  const int lower = rank_ > 0 ? rank_ - 1 : MPI_PROC_NULL;
  const int upper = rank_ + 1 < size_ ? rank_ + 1 : MPI_PROC_NULL;
  const int d = std::min(depth, k1 - k0);
  const std::size_t ps = static_cast<std::size_t>(planeSize);
  const std::size_t half = static_cast<std::size_t>(depth) * ps;
  buffer_.resize(2 * half);
  double* fromBelow = buffer_.data();
  double* fromAbove = buffer_.data() + half;
  // Both directions at once (one wait instead of two in a row): my top planes go up and the
  // lower block's land below k0; my bottom planes go down and the upper block's land from k1.
  MPI_Request requests[4];
  MPI_Irecv(fromBelow, depth * planeSize, MPI_DOUBLE, lower, kTagUp, comm_, &requests[0]);
  MPI_Irecv(fromAbove, depth * planeSize, MPI_DOUBLE, upper, kTagDown, comm_, &requests[1]);
  MPI_Isend(field.data() + static_cast<std::size_t>(k1 - d) * ps, d * planeSize, MPI_DOUBLE, upper,
            kTagUp, comm_, &requests[2]);
  MPI_Isend(field.data() + static_cast<std::size_t>(k0) * ps, d * planeSize, MPI_DOUBLE, lower,
            kTagDown, comm_, &requests[3]);
  MPI_Status statuses[4];
  MPI_Waitall(4, requests, statuses);
  int count = 0;
  if (lower != MPI_PROC_NULL) {
    MPI_Get_count(&statuses[0], MPI_DOUBLE, &count);
    const int planes = count / planeSize;
    const int first = std::max(0, k0 - planes);
    std::copy(fromBelow + static_cast<std::ptrdiff_t>((first - (k0 - planes)) * ps),
              fromBelow + static_cast<std::ptrdiff_t>(planes * ps),
              field.begin() + static_cast<std::ptrdiff_t>(first * ps));
  }
  if (upper != MPI_PROC_NULL) {
    MPI_Get_count(&statuses[1], MPI_DOUBLE, &count);
    const int planes = std::min(count / planeSize, planeCount - k1);
    std::copy(fromAbove, fromAbove + static_cast<std::ptrdiff_t>(planes * ps),
              field.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(k1) * ps));
  }
}

void MpiBlockComm::addHalo(std::vector<double>& field, int planeSize, int planeCount, int k0,
                           int k1) {
  const std::size_t ps = static_cast<std::size_t>(planeSize);
  buffer_.assign(2 * ps, 0.0);
  double* fromBelow = buffer_.data();
  double* fromAbove = buffer_.data() + ps;
  const int upper = rank_ + 1 < size_ ? rank_ + 1 : MPI_PROC_NULL;
  const int lower = rank_ > 0 ? rank_ - 1 : MPI_PROC_NULL;
  // Both directions at once: plane k1 (contributions to the upper block's first plane) goes up,
  // plane k0 - 1 goes down; the neighbours' contributions to planes k0 and k1 - 1 arrive.
  MPI_Request requests[4];
  MPI_Irecv(fromBelow, planeSize, MPI_DOUBLE, lower, kTagUp, comm_, &requests[0]);
  MPI_Irecv(fromAbove, planeSize, MPI_DOUBLE, upper, kTagDown, comm_, &requests[1]);
  const int upCount = (upper != MPI_PROC_NULL && k1 < planeCount) ? planeSize : 0;
  const int downCount = (lower != MPI_PROC_NULL && k0 > 0) ? planeSize : 0;
  MPI_Isend(field.data() + static_cast<std::size_t>(std::min(k1, planeCount - 1)) * ps, upCount,
            MPI_DOUBLE, upper, kTagUp, comm_, &requests[2]);
  MPI_Isend(field.data() + static_cast<std::size_t>(std::max(k0 - 1, 0)) * ps, downCount,
            MPI_DOUBLE, lower, kTagDown, comm_, &requests[3]);
  MPI_Waitall(4, requests, MPI_STATUSES_IGNORE);
  // Lower block's first, as when the two directions ran one after the other.
  if (lower != MPI_PROC_NULL) {
    for (std::size_t i = 0; i < ps; ++i)
      field[static_cast<std::size_t>(k0) * ps + i] += fromBelow[i];
  }
  if (upper != MPI_PROC_NULL) {
    for (std::size_t i = 0; i < ps; ++i) {
      field[static_cast<std::size_t>(k1 - 1) * ps + i] += fromAbove[i];
    }
  }
}

std::vector<double> MpiBlockComm::exchange(const std::vector<std::vector<double>>& outgoing,
                                           int stride) {
  (void)stride;
  std::vector<int> sendCounts(static_cast<std::size_t>(size_)), recvCounts(sendCounts.size());
  std::vector<int> sendOffsets(sendCounts.size()), recvOffsets(sendCounts.size());
  std::vector<double> send;
  for (int r = 0; r < size_; ++r) {
    const auto& o = outgoing[static_cast<std::size_t>(r)];
    sendOffsets[static_cast<std::size_t>(r)] = static_cast<int>(send.size());
    sendCounts[static_cast<std::size_t>(r)] = static_cast<int>(o.size());
    send.insert(send.end(), o.begin(), o.end());
  }
  MPI_Alltoall(sendCounts.data(), 1, MPI_INT, recvCounts.data(), 1, MPI_INT, comm_);
  int total = 0;
  for (int r = 0; r < size_; ++r) {
    recvOffsets[static_cast<std::size_t>(r)] = total;
    total += recvCounts[static_cast<std::size_t>(r)];
  }
  std::vector<double> received(static_cast<std::size_t>(total));
  MPI_Alltoallv(send.data(), sendCounts.data(), sendOffsets.data(), MPI_DOUBLE, received.data(),
                recvCounts.data(), recvOffsets.data(), MPI_DOUBLE, comm_);
  return received;
}

std::vector<float> MpiBlockComm::gatherToRoot(const std::vector<float>& values) {
  const int count = static_cast<int>(values.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), offsets(counts.size());
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  int total = 0;
  for (int r = 0; r < size_; ++r) {
    offsets[static_cast<std::size_t>(r)] = total;
    total += counts[static_cast<std::size_t>(r)];
  }
  std::vector<float> all(rank_ == 0 ? static_cast<std::size_t>(total) : 0);
  MPI_Gatherv(values.data(), count, MPI_FLOAT, all.data(), counts.data(), offsets.data(), MPI_FLOAT,
              0, comm_);
  return all;
}

}  // namespace vrflow::fluid
