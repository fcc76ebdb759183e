#pragma once
/// @file tools/report.h
/// @brief What the front end shows a person: progress bars on a terminal,
/// plain lines otherwise, and the per-stage timing/memory summary.

#include <cstdio>
#include <string>
#include <vector>

#include "core/progress.h"
#include "core/resources.h"
#include "scene/scene.h"

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

void printSummary(std::FILE* out, const std::vector<StageReport>& rows);

/// "warning: WARNING" on stderr.
void printWarning(const std::string& warning);

/// The scene's Scene::warnings on stderr, one "warning: ..." line each.
void printSceneWarnings(const Scene& scene);

}  // namespace lo::tool
