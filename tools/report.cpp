#include "report.h"

#include <unistd.h>

#include <algorithm>
#include <cinttypes>

namespace lo::tool {

ConsoleProgress::ConsoleProgress(bool quiet) : quiet_(quiet), tty_(isatty(fileno(stderr)) != 0) {}

void ConsoleProgress::begin(const std::string& task, size_t total) {
  task_ = task;
  lastQuarter_ = -1;
  clock_.reset();
  if (quiet_) return;
  if (tty_) {
    update(0, total);
  } else {
    std::fprintf(stderr, "%s: started (%s items)\n", task_.c_str(), formatCount(total).c_str());
  }
}

void ConsoleProgress::update(size_t done, size_t total) {
  if (quiet_) return;
  double f = total ? double(done) / double(total) : 1.0;
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = int(f * kWidth + 0.5);
    std::string bar(size_t(filled), '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "\r%-22s [%s] %5.1f%%  %6.1fs", task_.c_str(), bar.c_str(), 100.0 * f,
                 clock_.seconds());
    std::fflush(stderr);
  } else {
    int quarter = int(f * 4.0);
    if (quarter > lastQuarter_ && quarter > 0 && quarter < 4) {
      std::fprintf(stderr, "%s: %d%%\n", task_.c_str(), quarter * 25);
    }
    lastQuarter_ = std::max(lastQuarter_, quarter);
  }
}

void ConsoleProgress::end() {
  if (quiet_) return;
  if (tty_) {
    std::fprintf(stderr, "\n");
  } else {
    std::fprintf(stderr, "%s: done in %.2fs\n", task_.c_str(), clock_.seconds());
  }
}

void printSummary(std::FILE* out, const std::vector<StageReport>& rows) {
  double total = 0;
  std::fprintf(out, "\n%-18s %10s %12s %12s  %s\n", "stage", "time", "RSS after", "peak RSS",
               "result");
  for (const StageReport& r : rows) {
    total += r.seconds;
    std::fprintf(out, "%-18s %9.3fs %12s %12s  %s\n", r.name.c_str(), r.seconds,
                 formatBytes(r.rssBytes).c_str(), formatBytes(r.peakBytes).c_str(),
                 r.detail.c_str());
  }
  std::fprintf(out, "%-18s %9.3fs\n", "total", total);
}

void printWarning(const std::string& warning) {
  std::fprintf(stderr, "warning: %s\n", warning.c_str());
}

void printSceneWarnings(const Scene& scene) {
  for (const std::string& w : scene.warnings) printWarning(w);
  if (scene.rebased()) {
    std::fprintf(stderr,
                 "note: %s lies far from the origin; it is kept relative to its centre "
                 "(%.17g, %.17g, %.17g) so that float keeps its precision (--eye, --target, "
                 "--bounds and the .vdb stay in the file's coordinates)\n",
                 scene.sourcePath.c_str(), scene.origin.x, scene.origin.y, scene.origin.z);
  }
}

}  // namespace lo::tool
