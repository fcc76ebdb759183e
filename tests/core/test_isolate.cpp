// core/isolate.h: work on untrusted input in a child process, ended by its
// memory and time limits or by a crash, without harm to the caller.

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <thread>
#include <cstring>
#include <new>
#include <stdexcept>
#include <vector>

#include "core/isolate.h"
#include "test_util.h"

namespace lo {
namespace {

TEST(Isolate, FinishedWorkReturnsItsCodeAndMessage) {
  const IsolatedRun run = runIsolated(
      [](std::string& message) {
        message = "hello from the child";
        return 7;
      },
      IsolationLimits{});
  ASSERT_EQ(run.outcome, IsolatedRun::Outcome::Finished);
  EXPECT_EQ(run.exitCode, 7);
  EXPECT_EQ(run.message, "hello from the child");
  EXPECT_EQ(run.ToString(IsolationLimits{}), "");
}

TEST(Isolate, AnExceptionBecomesCode125WithItsText) {
  const IsolatedRun run = runIsolated(
      [](std::string&) -> int { throw std::runtime_error(std::string(5000, 'x')); },
      IsolationLimits{});
  ASSERT_EQ(run.outcome, IsolatedRun::Outcome::Finished);
  EXPECT_EQ(run.exitCode, 125);
  EXPECT_EQ(run.message.size(), kIsolatedMessageBytes);  // cut, not 5000 bytes
}

#if !defined(__SANITIZE_ADDRESS__)
TEST(Isolate, MemoryBeyondTheLimitIsOutOfMemory) {
  IsolationLimits limits;
  limits.memoryBytes = size_t(64) << 20;
  const IsolatedRun run = runIsolated(
      [](std::string&) {
        std::vector<char> big(size_t(1) << 30);  // 1 GiB against a 64 MiB limit
        big[12345] = 1;
        return int(big[12345]);
      },
      limits);
  EXPECT_EQ(run.outcome, IsolatedRun::Outcome::OutOfMemory);
  EXPECT_FALSE(run.outOfTheProcessMemory(limits));
  EXPECT_NE(run.ToString(limits).find("more than 64.0 MiB"), std::string::npos)
      << run.ToString(limits);
}

// An allocation that fails on a thread of the work, where no catch takes it,
// ends in std::terminate: out of memory, not a crash (OpenVDB reads with
// threads; a valid .vdb under ulimit -v was "damaged: crashed the reader").
TEST(Isolate, MemoryBeyondTheLimitOnAThreadIsOutOfMemory) {
  IsolationLimits limits;
  limits.memoryBytes = size_t(64) << 20;
  const IsolatedRun run = runIsolated(
      [](std::string&) {
        int value = 0;
        std::thread([&value] {
          std::vector<char> big(size_t(1) << 30);  // 1 GiB against a 64 MiB limit
          big[12345] = 1;
          value = big[12345];
        }).join();
        return value;
      },
      limits);
  EXPECT_EQ(run.outcome, IsolatedRun::Outcome::OutOfMemory) << run.ToString(limits);
}

// Under the process's own address-space limit (ulimit -v) the work has less
// than its limit: running out of it says so, and names the process's limit
// (a valid .vdb read under ulimit -v 200 MB was called damaged: "reading it
// needed more than 551.5 MiB of memory").
TEST(Isolate, OutOfMemoryUnderTheProcesssOwnLimitSaysSo) {
  // The limit is set in a child, not in the tests' process.
  const std::string text = test::textFromChild([] {
    const size_t vm = [] {
      std::FILE* f = std::fopen("/proc/self/statm", "r");
      unsigned long pages = 0;
      if (f) {
        if (std::fscanf(f, "%lu", &pages) != 1) pages = 0;
        std::fclose(f);
      }
      return size_t(pages) * size_t(sysconf(_SC_PAGESIZE));
    }();
    const rlim_t cap = rlim_t(vm + (size_t(128) << 20));
    const rlimit as{cap, cap};
    if (vm == 0 || setrlimit(RLIMIT_AS, &as) != 0) std::_Exit(2);
    IsolationLimits limits;
    limits.memoryBytes = size_t(1) << 30;
    const IsolatedRun run = runIsolated(
        [](std::string&) {
          std::vector<char> big(size_t(512) << 20);  // within 1 GiB, beyond the 128 MiB left
          big[12345] = 1;
          return int(big[12345]);
        },
        limits);
    return std::to_string(int(run.outcome)) + " " +
           std::to_string(int(run.outOfTheProcessMemory(limits))) + " " + run.ToString(limits);
  });
  EXPECT_EQ(text.rfind(std::to_string(int(IsolatedRun::Outcome::OutOfMemory)) + " 1 ran out of "
                       "memory (it may take up to 1.00 GiB): the process's address space is "
                       "limited to ",
                       0),
            0u)
      << text;
  EXPECT_NE(text.find("(ulimit -v)"), std::string::npos) << text;
}
#endif

TEST(Isolate, AnEndlessLoopIsKilledAtTheTimeLimit) {
  IsolationLimits limits;
  limits.seconds = 0.5;
  const auto start = std::chrono::steady_clock::now();
  const IsolatedRun run = runIsolated(
      [](std::string&) {
        volatile unsigned long n = 0;
        for (;;) n = n + 1;
        return 0;
      },
      limits);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(run.outcome, IsolatedRun::Outcome::TimedOut);
  EXPECT_LT(seconds, 5.0);
}

TEST(Isolate, AChildThatWaitsPastTheLimitDidNotUseItsCpu) {
  // What a lock held at the fork looks like: a wait, not a computation; the
  // .vdb reader tries such a read once more (a looping one it does not).
  IsolationLimits limits;
  limits.seconds = 0.3;
  const IsolatedRun run = runIsolated(
      [](std::string&) {
        std::this_thread::sleep_for(std::chrono::seconds(5));
        return 0;
      },
      limits);
  EXPECT_EQ(run.outcome, IsolatedRun::Outcome::TimedOut);
  EXPECT_FALSE(run.usedItsCpu);
}

TEST(Isolate, ACrashIsReportedNotSuffered) {
  const IsolatedRun run = runIsolated(
      [](std::string&) {
        raise(SIGSEGV);
        return 0;
      },
      IsolationLimits{});
  EXPECT_EQ(run.outcome, IsolatedRun::Outcome::Crashed);
  EXPECT_EQ(run.signal, SIGSEGV);
  EXPECT_NE(run.ToString(IsolationLimits{}).find("crashed"), std::string::npos);
}

}  // namespace
}  // namespace lo
