#pragma once
/// @file core/progress.h
/// @brief Progress reporting from stages to the front end.
///
/// A stage receives a ProgressSink* (may be null) and wraps its work in a
/// Progress. Progress::advance is thread-safe and cheap: it only calls the sink
/// when a new percent is reached or a quarter of a second passed since the
/// last report (a front end hears Ctrl-C at a report), under a mutex, so TBB
/// bodies may call it.

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace lo {

/// Implemented by the front end (a terminal bar, plain lines, or nothing).
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void begin(const std::string& task, size_t total) = 0;
  /// Called with a monotonically increasing `done` (<= total).
  virtual void update(size_t done, size_t total) = 0;
  virtual void end() = 0;
};

class Progress {
 public:
  Progress(ProgressSink* sink, const std::string& task, size_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(size_t n = 1);
  /// Reports again what is done so far when a quarter of a second passed
  /// since the last report, for work that cannot say how far it got (a pass
  /// of a path tracer under a time budget, the direct light of a lightmap
  /// page): a front end still hears Ctrl-C there. Never the last report.
  void heartbeat();

 private:
  ProgressSink* sink_;
  size_t total_;
  std::atomic<size_t> done_{0};
  std::atomic<size_t> nextReport_{0};
  /// When the next report is due whatever the percent (steady clock ticks).
  std::atomic<std::chrono::steady_clock::rep> nextReportTime_{0};
  std::mutex mutex_;
  size_t reported_ = 0;
};

}  // namespace lo
