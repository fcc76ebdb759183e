// runThreadRanks: a Communicator over threads of one process. Each
// collective publishes a pointer to the rank's data, meets the others at a
// barrier, reads what it needs from their data, and meets them again before
// anyone may change or free it.

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "core/error.h"
#include "distributed/communicator.h"

namespace lo {

namespace distributed_internal {

/// What the ranks of one runThreadRanks share.
class ThreadGroup {
 public:
  explicit ThreadGroup(int ranks)
      : ranks_(ranks), slots_(size_t(ranks), nullptr), slots2_(size_t(ranks), nullptr) {}

  int ranks() const { return ranks_; }

  /// Every rank arrives before any leaves. @throws std::runtime_error once
  /// a rank has failed.
  void barrier() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (aborted_) throw std::runtime_error("another rank failed");
    const uint64_t generation = generation_;
    if (++arrived_ == ranks_) {
      arrived_ = 0;
      ++generation_;
      changed_.notify_all();
      return;
    }
    changed_.wait(lock, [&] { return generation_ != generation || aborted_; });
    if (aborted_) throw std::runtime_error("another rank failed");
  }

  void abort() {
    std::lock_guard<std::mutex> lock(mutex_);
    aborted_ = true;
    changed_.notify_all();
  }

  /// Per-rank pointers published for the current collective.
  std::vector<const void*>& slots() { return slots_; }
  std::vector<const void*>& slots2() { return slots2_; }

 private:
  const int ranks_;
  std::mutex mutex_;
  std::condition_variable changed_;
  int arrived_ = 0;
  uint64_t generation_ = 0;
  bool aborted_ = false;
  std::vector<const void*> slots_, slots2_;
};

class ThreadCommunicator final : public Communicator {
 public:
  ThreadCommunicator(ThreadGroup& group, int rank) : group_(group), rank_(rank) {}
  int rank() const override { return rank_; }
  int size() const override { return group_.ranks(); }

  void allreduceSum(uint64_t* values, size_t n) override {
    std::vector<uint64_t> mine(values, values + n);
    publish(mine.data());
    for (size_t i = 0; i < n; ++i) {
      uint64_t sum = 0;
      for (int r = 0; r < size(); ++r) sum += static_cast<const uint64_t*>(slot(r))[i];
      values[i] = sum;
    }
    group_.barrier();
  }

  void allreduceMax(double* values, size_t n) override {
    std::vector<double> mine(values, values + n);
    publish(mine.data());
    for (size_t i = 0; i < n; ++i) {
      double m = static_cast<const double*>(slot(0))[i];
      for (int r = 1; r < size(); ++r) m = std::max(m, static_cast<const double*>(slot(r))[i]);
      values[i] = m;
    }
    group_.barrier();
  }

  std::vector<uint64_t> allgather(uint64_t value) override {
    publish(&value);
    std::vector<uint64_t> out(static_cast<size_t>(size()));
    for (int r = 0; r < size(); ++r) out[size_t(r)] = *static_cast<const uint64_t*>(slot(r));
    group_.barrier();
    return out;
  }

  std::vector<uint64_t> alltoallCounts(const std::vector<uint64_t>& counts) override {
    LO_CHECK_EQ(counts.size(), size_t(size()));
    publish(counts.data());
    std::vector<uint64_t> out(static_cast<size_t>(size()));
    for (int r = 0; r < size(); ++r) {
      out[size_t(r)] = static_cast<const uint64_t*>(slot(r))[rank_];
    }
    group_.barrier();
    return out;
  }

  void alltoallv(const void* send, const std::vector<uint64_t>& sendBytes, void* recv,
                 const std::vector<uint64_t>& recvBytes) override {
    LO_CHECK_EQ(sendBytes.size(), size_t(size()));
    LO_CHECK_EQ(recvBytes.size(), size_t(size()));
    group_.slots2()[size_t(rank_)] = sendBytes.data();
    publish(send);
    char* out = static_cast<char*>(recv);
    for (int r = 0; r < size(); ++r) {
      const uint64_t* theirCounts = static_cast<const uint64_t*>(group_.slots2()[size_t(r)]);
      uint64_t offset = 0;
      for (int q = 0; q < rank_; ++q) offset += theirCounts[q];
      LO_CHECK_EQ(theirCounts[rank_], recvBytes[size_t(r)]);
      if (recvBytes[size_t(r)] > 0) {
        std::memcpy(out, static_cast<const char*>(slot(r)) + offset, size_t(recvBytes[size_t(r)]));
      }
      out += recvBytes[size_t(r)];
    }
    group_.barrier();
  }

  std::vector<std::vector<char>> gatherBytes(const std::vector<char>& bytes, int root) override {
    publish(&bytes);
    std::vector<std::vector<char>> out;
    if (rank_ == root) {
      for (int r = 0; r < size(); ++r) {
        out.push_back(*static_cast<const std::vector<char>*>(slot(r)));
      }
    }
    group_.barrier();
    return out;
  }

 private:
  void publish(const void* data) {
    group_.slots()[size_t(rank_)] = data;
    group_.barrier();
  }
  const void* slot(int r) const { return group_.slots()[size_t(r)]; }

  ThreadGroup& group_;
  const int rank_;
};

}  // namespace distributed_internal

void runThreadRanks(int ranks, const std::function<void(Communicator&)>& body) {
  using namespace distributed_internal;
  if (ranks < 1) throw InputError("ranks " + std::to_string(ranks) + " must be at least 1");
  ThreadGroup group(ranks);
  std::mutex errorMutex;
  std::exception_ptr first;
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r) {
    threads.emplace_back([&, r] {
      ThreadCommunicator comm(group, r);
      try {
        body(comm);
      } catch (...) {
        {
          std::lock_guard<std::mutex> lock(errorMutex);
          if (!first) first = std::current_exception();
        }
        group.abort();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  if (first) std::rethrow_exception(first);
}

}  // namespace lo
