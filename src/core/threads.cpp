#include "core/threads.h"

#include <tbb/global_control.h>

#include <sched.h>
#include <unistd.h>

#include <optional>

namespace lo {

struct ThreadLimit::Impl {
  std::optional<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : impl_(std::make_unique<Impl>()) {
  if (threads > 0) {
    impl_->control.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
  }
}

ThreadLimit::~ThreadLimit() = default;

int usableCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return hardwareThreads();
  return CPU_COUNT(&set);
}

int hardwareThreads() {
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? int(n) : 1;
}

}  // namespace lo
