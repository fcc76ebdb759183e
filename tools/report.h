#pragma once
/// @file tools/report.h
/// @brief What the front end shows a person: progress bars on a terminal,
/// plain lines otherwise, and the per-stage timing/memory summary.

#include <cstdio>
#include <string>
#include <vector>

#include "core/progress.h"
#include "core/resources.h"

namespace lo::tool {

/// Progress on stderr: an in-place bar when stderr is a terminal, otherwise
/// one line at the start and one at the end of each task (plus every 25%).
class ConsoleProgress : public ProgressSink {
 public:
  explicit ConsoleProgress(bool quiet);
  void begin(const std::string& task, size_t total) override;
  void update(size_t done, size_t total) override;
  void end() override;

 private:
  bool quiet_;
  bool tty_;
  std::string task_;
  int lastQuarter_ = -1;
  Stopwatch clock_;
};

/// One row of the closing summary.
struct StageReport {
  std::string name;
  double seconds = 0;
  size_t rssBytes = 0;   ///< resident set size after the stage
  size_t peakBytes = 0;  ///< peak resident set size so far
  std::string detail;    ///< e.g. "612,004 photons"
};

/// Times a stage and appends its row on finish().
class StageTimer {
 public:
  StageTimer(std::vector<StageReport>& rows, std::string name);
  void finish(std::string detail = "");

 private:
  std::vector<StageReport>& rows_;
  std::string name_;
  Stopwatch clock_;
};

void printSummary(std::FILE* out, const std::vector<StageReport>& rows);
std::string formatBytes(size_t bytes);
std::string formatCount(size_t n);  ///< 1234567 -> "1,234,567"

}  // namespace lo::tool
