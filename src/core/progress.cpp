#include "core/progress.h"

#include <sstream>

#include "core/math.h"

namespace lo {

std::string Vec3::ToString() const {
  std::ostringstream os;
  os << "[" << x << ", " << y << ", " << z << "]";
  return os.str();
}

std::string Coord::ToString() const {
  std::ostringstream os;
  os << "(" << x << ", " << y << ", " << z << ")";
  return os.str();
}

std::string Bounds3::ToString() const {
  return "[ " + lower.ToString() + " - " + upper.ToString() + " ]";
}

namespace {

/// The longest a stage goes without a report while it advances.
constexpr std::chrono::milliseconds kReportInterval{250};

std::chrono::steady_clock::rep reportDue() {
  return (std::chrono::steady_clock::now() + kReportInterval).time_since_epoch().count();
}

}  // namespace

Progress::Progress(ProgressSink* sink, const std::string& task, size_t total)
    : sink_(sink), total_(total) {
  nextReport_ = total_ / 100 + 1;
  nextReportTime_ = reportDue();
  if (sink_) sink_->begin(task, total_);
}

Progress::~Progress() {
  if (sink_) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (reported_ < total_) sink_->update(total_, total_);
    sink_->end();
  }
}

void Progress::advance(size_t n) {
  size_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (!sink_) return;
  if (done < nextReport_.load(std::memory_order_relaxed) &&
      std::chrono::steady_clock::now().time_since_epoch().count() <
          nextReportTime_.load(std::memory_order_relaxed)) {
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (done <= reported_) return;
  reported_ = std::min(done, total_);
  nextReport_.store(done + total_ / 100 + 1, std::memory_order_relaxed);
  nextReportTime_.store(reportDue(), std::memory_order_relaxed);
  sink_->update(reported_, total_);
}

void Progress::heartbeat() {
  if (!sink_ || std::chrono::steady_clock::now().time_since_epoch().count() <
                    nextReportTime_.load(std::memory_order_relaxed)) {
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (reported_ >= total_) return;
  nextReportTime_.store(reportDue(), std::memory_order_relaxed);
  sink_->update(reported_, total_);
}

}  // namespace lo
