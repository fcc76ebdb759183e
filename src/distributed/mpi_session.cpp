// MpiSession over OpenMPI (or any MPI 3): the one translation unit that
// includes mpi.h. Large messages go in pieces of at most 1 GiB, so that the
// int counts of MPI's calls never overflow.

#include "distributed/mpi_session.h"

#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/error.h"

namespace lo {

namespace distributed_internal {

constexpr uint64_t kMaxMessageBytes = uint64_t(1) << 30;

/// Posts the receives or sends of `bytes` bytes at `data` with rank `peer`,
/// in pieces of at most kMaxMessageBytes (tags 0, 1, ...).
void postPieces(bool receive, char* data, uint64_t bytes, int peer,
                std::vector<MPI_Request>& requests) {
  int tag = 0;
  for (uint64_t offset = 0; offset < bytes; offset += kMaxMessageBytes, ++tag) {
    const int count = int(std::min(kMaxMessageBytes, bytes - offset));
    requests.emplace_back();
    if (receive) {
      MPI_Irecv(data + offset, count, MPI_BYTE, peer, tag, MPI_COMM_WORLD, &requests.back());
    } else {
      MPI_Isend(data + offset, count, MPI_BYTE, peer, tag, MPI_COMM_WORLD, &requests.back());
    }
  }
}

class MpiCommunicator final : public Communicator {
 public:
  MpiCommunicator() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void allreduceSum(uint64_t* values, size_t n) override {
    MPI_Allreduce(MPI_IN_PLACE, values, int(n), MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
  }
  void allreduceMax(double* values, size_t n) override {
    MPI_Allreduce(MPI_IN_PLACE, values, int(n), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  }
  std::vector<uint64_t> allgather(uint64_t value) override {
    std::vector<uint64_t> out(static_cast<size_t>(size_));
    MPI_Allgather(&value, 1, MPI_UINT64_T, out.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
    return out;
  }
  std::vector<uint64_t> alltoallCounts(const std::vector<uint64_t>& counts) override {
    LO_CHECK_EQ(counts.size(), size_t(size_));
    std::vector<uint64_t> out(static_cast<size_t>(size_));
    MPI_Alltoall(counts.data(), 1, MPI_UINT64_T, out.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
    return out;
  }
  void alltoallv(const void* send, const std::vector<uint64_t>& sendBytes, void* recv,
                 const std::vector<uint64_t>& recvBytes) override {
    std::vector<MPI_Request> requests;
    char* in = static_cast<char*>(recv);
    char* out = const_cast<char*>(static_cast<const char*>(send));  // MPI 2 signatures
    const char* mine = nullptr;
    char* mineTo = nullptr;
    for (int r = 0; r < size_; ++r) {
      if (r == rank_) {
        mineTo = in;
      } else {
        postPieces(true, in, recvBytes[size_t(r)], r, requests);
      }
      in += recvBytes[size_t(r)];
    }
    for (int r = 0; r < size_; ++r) {
      if (r == rank_) {
        mine = out;
      } else {
        postPieces(false, out, sendBytes[size_t(r)], r, requests);
      }
      out += sendBytes[size_t(r)];
    }
    LO_CHECK_EQ(sendBytes[size_t(rank_)], recvBytes[size_t(rank_)]);
    if (sendBytes[size_t(rank_)] > 0) std::memcpy(mineTo, mine, size_t(sendBytes[size_t(rank_)]));
    MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  }
  std::vector<std::vector<char>> gatherBytes(const std::vector<char>& bytes, int root) override {
    const uint64_t mine = bytes.size();
    std::vector<uint64_t> sizes(static_cast<size_t>(size_));
    MPI_Gather(&mine, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, root, MPI_COMM_WORLD);
    std::vector<MPI_Request> requests;
    std::vector<std::vector<char>> out;
    if (rank_ == root) {
      out.resize(static_cast<size_t>(size_));
      for (int r = 0; r < size_; ++r) {
        if (r == root) {
          out[size_t(r)] = bytes;
          continue;
        }
        out[size_t(r)].resize(size_t(sizes[size_t(r)]));
        postPieces(true, out[size_t(r)].data(), sizes[size_t(r)], r, requests);
      }
    } else {
      postPieces(false, const_cast<char*>(bytes.data()), mine, root, requests);
    }
    MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    return out;
  }

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace distributed_internal

struct MpiSession::State {
  std::unique_ptr<distributed_internal::MpiCommunicator> world;
};

bool mpiAvailable() { return true; }

MpiSession::MpiSession() : state_(std::make_unique<State>()) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw InputError("the MPI library gives thread level " + std::to_string(provided) +
                     ", below the MPI_THREAD_FUNNELED the bake needs");
  }
  state_->world = std::make_unique<distributed_internal::MpiCommunicator>();
}

MpiSession::~MpiSession() {
  state_->world.reset();
  MPI_Finalize();
}

Communicator& MpiSession::world() { return *state_->world; }

void MpiSession::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

}  // namespace lo
