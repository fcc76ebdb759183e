#include "core/threads.h"

#include <tbb/global_control.h>

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

}  // namespace lo
