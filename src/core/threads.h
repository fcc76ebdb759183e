#pragma once
/// @file core/threads.h
/// @brief The worker-thread limit of a command (`--threads N`): one place
/// that talks to TBB's global control, so tools do not.

#include <memory>

namespace lo {

/// Limits TBB's parallelism to `threads` while alive; 0 = all cores. Results
/// never depend on it (every parallel stage is deterministic).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Cores this process may run on (its CPU affinity mask), and the machine's
/// hardware threads: fewer usable than present means a launcher pinned the
/// process (mpirun binds each rank to one core by default).
int usableCores();
int hardwareThreads();

}  // namespace lo
