#pragma once
/// @file core/resources.h
/// @brief Wall-clock stopwatch, process memory figures and the per-stage rows
/// that stages record and the front end prints.

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

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
/// Address space this process maps now, bytes (/proc/self/statm's first
/// field: what an address-space limit, ulimit -v, counts); 0 if unavailable.
size_t mappedBytes();
/// Resets the kernel's peak resident set size of this process to the current
/// one (Linux >= 4.0, /proc/self/clear_refs), so that peakRssSinceResetBytes
/// measures one piece of work in a process that did others before. False when
/// the kernel refuses (then the peak is the process's whole life).
bool resetPeakRss();
/// Peak resident set size since the last resetPeakRss (VmHWM of
/// /proc/self/status), bytes; 0 if unavailable.
size_t peakRssSinceResetBytes();

/// Memory the kernel says a new allocation can get without swapping
/// (MemAvailable of /proc/meminfo, capped by the cgroup's limit when one is
/// set, and by the environment variable LIGHTOCTREE_MEMORY_LIMIT when set:
/// bytes, or a number with K, M, G or T, binary: 2G = 2 GiB), bytes; 0 if
/// unknown. @throws InputError when LIGHTOCTREE_MEMORY_LIMIT is not a size.
size_t availableMemoryBytes();

/// LIGHTOCTREE_MEMORY_LIMIT in bytes (see availableMemoryBytes); 0 when the
/// variable is not set. @throws InputError when it is not a size.
size_t memoryLimitSetting();

/// The test hook `name`'s value (an environment variable the tests set:
/// LIGHTOCTREE_PAUSE_SET, LIGHTOCTREE_KILL_RANK), only where
/// LIGHTOCTREE_TEST_HOOKS=1 says a test runs: the variable alone, left in a
/// user's environment, paused every run forever or killed a rank of every
/// job (H16-3-1). "" otherwise.
std::string testHook(const char* name);

/// What the process's address-space limit (setrlimit RLIMIT_AS, `ulimit -v`)
/// leaves: its soft limit less the address space in use now (VmSize), bytes;
/// SIZE_MAX when there is no limit. Every allocation counts against it,
/// resident or not, so availableMemoryBytes takes it as a cap too.
size_t addressSpaceRoomBytes();

/// How many more threads the process may start now: what `ulimit -u`
/// (RLIMIT_NPROC, counted over every thread of the process's real user)
/// and a container's pids limit (cgroup pids.max less pids.current) leave,
/// the smaller; -1 when neither holds (no limit, or a root process, which
/// RLIMIT_NPROC does not hold).
long threadRoom();

/// @brief For the message of an allocation that failed inside a library (a
/// shared library that could not be mapped, a device that could not be
/// made): under an address-space limit, "the process's address space is
/// limited to 195.3 MiB (ulimit -v), 2.1 MiB of it unused: raise or remove
/// the limit"; else the memory available (availableMemoryBytes). Their own
/// messages said only "error 4", or advised installing what was installed.
std::string memoryShortfall();

/// @brief Watches the process's resident memory from a thread of its own
/// (every `intervalSeconds`) and calls `onExceeded(rss)` once, from that
/// thread, when it grows past `limitBytes`: the estimates made before the
/// work (photons, voxels, atlas pages) cannot see everything that grows, and
/// a limit the user set (LIGHTOCTREE_MEMORY_LIMIT) must hold whatever grew.
/// The destructor stops the thread. A limit of 0 watches nothing.
class MemoryWatch {
 public:
  MemoryWatch(size_t limitBytes, std::function<void(size_t rssBytes)> onExceeded,
              double intervalSeconds = 0.02);
  ~MemoryWatch();
  MemoryWatch(const MemoryWatch&) = delete;
  MemoryWatch& operator=(const MemoryWatch&) = delete;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// One stage's row in a report.
struct StageReport {
  std::string name;
  double seconds = 0;
  size_t rssBytes = 0;   ///< resident set size after the stage
  size_t peakBytes = 0;  ///< peak resident set size so far
  std::string detail;    ///< e.g. "612,004 photons"
};

/// Times a stage and appends its row to `rows` on finish().
class StageTimer {
 public:
  StageTimer(std::vector<StageReport>& rows, std::string name);
  /// Appends the row; returns the stage's seconds.
  double finish(std::string detail = "");

 private:
  std::vector<StageReport>& rows_;
  std::string name_;
  Stopwatch clock_;
};

/// Gives the pages of freed heap blocks back to the system (glibc's
/// malloc_trim; nothing elsewhere). Large buffers freed in the middle of the
/// heap otherwise stay in the process's resident memory.
void returnFreeMemory();

std::string formatBytes(size_t bytes);  ///< "12.3 MiB"
std::string formatCount(size_t n);      ///< 1234567 -> "1,234,567"
std::string formatNumber(double v);     ///< shortest text, as std::ostream prints it: "1.5", "600000"

}  // namespace lo
