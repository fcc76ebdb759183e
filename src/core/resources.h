#pragma once
/// @file core/resources.h
/// @brief Wall-clock stopwatch and process memory figures for stage reports.

#include <chrono>
#include <cstddef>

namespace lo {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void reset() { start_ = std::chrono::steady_clock::now(); }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// Peak resident set size of this process so far, bytes (getrusage).
size_t peakRssBytes();
/// Current resident set size, bytes (/proc/self/statm); 0 if unavailable.
size_t currentRssBytes();

}  // namespace lo
