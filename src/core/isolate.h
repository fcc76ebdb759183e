#pragma once
/// @file core/isolate.h
/// @brief Runs a piece of work on untrusted input in a child process under a
/// memory and time limit (docs/robustness.md, "Reading untrusted files"). A
/// damaged file can make a third-party reader allocate gigabytes, loop for
/// minutes or corrupt the heap; in the child that costs a refusal, not the
/// caller's process. POSIX (fork); the work must not need other threads.

#include <cstddef>
#include <functional>
#include <string>

namespace lo {

struct IsolationLimits {
  size_t memoryBytes = size_t(1) << 30;  ///< address space the work may add
  double seconds = 20;                   ///< wall-clock and CPU time
};

struct IsolatedRun {
  enum class Outcome {
    Finished,     ///< the work returned; `exitCode` is its return value
    OutOfMemory,  ///< it threw std::bad_alloc under the memory limit
    TimedOut,     ///< killed at the time limit
    Crashed,      ///< ended by a signal (`signal`): a segfault, an abort
    NotIsolated,  ///< fork failed: the caller decides (e.g. runs the work itself)
  };
  Outcome outcome = Outcome::NotIsolated;
  int exitCode = 0;
  int signal = 0;
  /// TimedOut by its CPU limit: it computed all along (a reader looping on
  /// a damaged file), rather than waiting past the wall-clock limit (e.g.
  /// on a lock held at the fork), so trying again would only repeat it.
  bool usedItsCpu = false;
  /// What the work put in its message (at most kIsolatedMessageBytes), e.g.
  /// the text of the exception that ended it.
  std::string message;
  /// The address space the work could add: the limit's memoryBytes, or less
  /// where the process's own hard limit (ulimit -v) leaves less; the child
  /// then has all that limit leaves.
  size_t memoryBytes = 0;
  /// Out of memory with less than the limit's memoryBytes: the process's
  /// own address-space limit ended the work, not what it was given to read
  /// (a valid .vdb under ulimit -v 200 MB was called damaged).
  bool outOfTheProcessMemory(const IsolationLimits& limits) const {
    return outcome == Outcome::OutOfMemory && memoryBytes < limits.memoryBytes;
  }
  /// One sentence for an error message, e.g. "needed more than 1.00 GiB of
  /// memory", or when outOfTheProcessMemory "ran out of memory: the
  /// process's address space is limited to ... (ulimit -v) ..."
  /// (memoryShortfall); empty when Finished.
  std::string ToString(const IsolationLimits& limits) const;
};

/// Longest message a child passes back; longer ones are cut there.
constexpr size_t kIsolatedMessageBytes = 2000;

/// Runs `work` in a forked child under `limits` and reports how it ended.
/// The child's return value is its exit code (0-123) and `message` (set by
/// the work) comes back in IsolatedRun::message; an exception other than
/// std::bad_alloc ends it with exit code 125 and its what() as the message.
/// Under AddressSanitizer the memory limit is not applied (its shadow memory
/// needs the address space).
IsolatedRun runIsolated(const std::function<int(std::string& message)>& work,
                        const IsolationLimits& limits);

}  // namespace lo
