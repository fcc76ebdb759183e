// core/isolate.h: work on untrusted input in a child process, ended by its
// memory and time limits or by a crash, without harm to the caller.

#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <thread>
#include <cstring>
#include <new>
#include <stdexcept>
#include <vector>

#include "core/isolate.h"

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
  EXPECT_NE(run.ToString(limits).find("more than 64.0 MiB"), std::string::npos)
      << run.ToString(limits);
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
