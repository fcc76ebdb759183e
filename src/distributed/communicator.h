#pragma once
/// @file distributed/communicator.h
/// @brief The collective operations a distributed bake needs, over any set
/// of processes (ranks): MPI_COMM_WORLD (distributed/mpi_session.h, the only
/// place that sees MPI) or threads of one process (runThreadRanks: the tests
/// run every distributed path without mpirun). Every rank calls the same
/// operations in the same order; each returns only once every rank took part.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace lo {

class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;

  /// Element-wise sum (max) over the ranks of `values[0 .. n)`, in place:
  /// every rank ends with the result.
  virtual void allreduceSum(uint64_t* values, size_t n) = 0;
  virtual void allreduceMax(double* values, size_t n) = 0;
  /// Every rank's `value`, in rank order.
  virtual std::vector<uint64_t> allgather(uint64_t value) = 0;
  /// Each rank sends `sendBytes[r]` bytes to rank r, taken from `send` in
  /// rank order (rank r's bytes start after those of ranks < r), and
  /// receives `recvBytes[r]` from rank r into `recv`, likewise in rank order.
  /// The counts must agree (alltoallCounts gives them); any size, 2 GiB and
  /// beyond included.
  virtual void alltoallv(const void* send, const std::vector<uint64_t>& sendBytes, void* recv,
                         const std::vector<uint64_t>& recvBytes) = 0;
  /// counts[r] is what this rank sends to rank r; returns what each rank
  /// sends to this one.
  virtual std::vector<uint64_t> alltoallCounts(const std::vector<uint64_t>& counts) = 0;
  /// Rank `root` receives every rank's bytes in rank order (its own
  /// included); the other ranks get an empty vector.
  virtual std::vector<std::vector<char>> gatherBytes(const std::vector<char>& bytes, int root) = 0;
};

/// Sends items[begin[r] .. begin[r + 1]) to rank r (items grouped by
/// destination, `begin` of size() + 1) and appends what every rank sent here,
/// in rank order, to `received`. T must be trivially copyable. Returns the
/// bytes sent to other ranks.
template <typename T>
uint64_t exchangeItems(Communicator& comm, const std::vector<T>& items,
                       const std::vector<uint64_t>& begin, std::vector<T>& received) {
  const int n = comm.size();
  std::vector<uint64_t> sendBytes(size_t(n), 0);
  uint64_t sent = 0;
  for (int r = 0; r < n; ++r) {
    sendBytes[size_t(r)] = (begin[size_t(r) + 1] - begin[size_t(r)]) * sizeof(T);
    if (r != comm.rank()) sent += sendBytes[size_t(r)];
  }
  const std::vector<uint64_t> recvBytes = comm.alltoallCounts(sendBytes);
  uint64_t total = 0;
  for (uint64_t b : recvBytes) total += b;
  const size_t old = received.size();
  received.resize(old + size_t(total / sizeof(T)));
  comm.alltoallv(items.data(), sendBytes, received.data() + old, recvBytes);
  return sent;
}

/// Runs `body` on `ranks` threads of this process, each with its own
/// Communicator of that many ranks, and waits for them. When a rank throws,
/// the others' pending and later collectives throw too (nobody waits
/// forever) and the first exception is rethrown here.
void runThreadRanks(int ranks, const std::function<void(Communicator&)>& body);

}  // namespace lo
