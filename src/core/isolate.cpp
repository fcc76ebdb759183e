#include "core/isolate.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <exception>
#include <new>
#include <system_error>
#include <thread>

#include "core/resources.h"

// Sanitizer runtimes (AddressSanitizer, libFuzzer's) call a death callback
// when they report an error; a fuzzer's dumps the current input as a finding.
// In the child an error is the refusal the caller expects: the child's
// callback ends it by SIGABRT, a crash, as it would end without a sanitizer
// (the runtime's own exit code, 1, would read as a reader's ordinary
// refusal). Weak: absent without a sanitizer.
extern "C" void __sanitizer_set_death_callback(void (*callback)(void)) __attribute__((weak));

namespace lo {

namespace {

/// The child's sanitizer death callback: a report is a crash of the reader.
void dieAsACrash() {
  signal(SIGABRT, SIG_DFL);
  raise(SIGABRT);
  _exit(134);
}

/// The child's std::terminate: an allocation that failed on a thread of the
/// work (OpenVDB reads with TBB), where no catch takes it, or a thread that
/// could not be started for want of address space, is out of memory (exit
/// code 124), not a crash: a valid .vdb under ulimit -v was called damaged
/// ("crashed the reader (signal 6)").
[[noreturn]] void terminateOutOfMemory() {
  if (const std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      _exit(124);
    } catch (const std::system_error& error) {
      if (error.code() == std::errc::resource_unavailable_try_again) _exit(124);
    } catch (...) {
    }
  }
  signal(SIGABRT, SIG_DFL);
  abort();
}

/// Virtual memory of this process now (VmSize), bytes; 0 if unknown. Plain
/// system calls: it runs in the forked child, where only async-signal-safe
/// work is sure not to wait on a lock another thread of the parent held.
size_t virtualBytes() {
  const int fd = open("/proc/self/statm", O_RDONLY);
  if (fd < 0) return 0;
  char text[64];
  const ssize_t n = read(fd, text, sizeof text - 1);
  close(fd);
  if (n <= 0) return 0;
  size_t pages = 0;
  for (ssize_t i = 0; i < n && text[i] >= '0' && text[i] <= '9'; ++i) {
    pages = pages * 10 + size_t(text[i] - '0');
  }
  return pages * size_t(sysconf(_SC_PAGESIZE));
}

}  // namespace

std::string IsolatedRun::ToString(const IsolationLimits& limits) const {
  char text[160];
  switch (outcome) {
    case Outcome::Finished:
      return "";
    case Outcome::OutOfMemory:
      if (outOfTheProcessMemory(limits)) {
        return "ran out of memory (it may take up to " + formatBytes(limits.memoryBytes) +
               "): " + memoryShortfall();
      }
      return "needed more than " + formatBytes(limits.memoryBytes) + " of memory";
    case Outcome::TimedOut:
      std::snprintf(text, sizeof text, "took longer than %.0f s", limits.seconds);
      return text;
    case Outcome::Crashed:
      return std::string("crashed the reader (signal ") + std::to_string(signal) + ", " +
             strsignal(signal) + ")";
    case Outcome::NotIsolated:
      return "could not be read in a separate process";
  }
  return "";
}

IsolatedRun runIsolated(const std::function<int(std::string& message)>& work,
                        const IsolationLimits& limits) {
  IsolatedRun run;
  // What the child may add: the limit, or what the process's hard limit on
  // its address space leaves (the child cannot raise its limit past it).
  run.memoryBytes = limits.memoryBytes;
#if !defined(__SANITIZE_ADDRESS__)
  rlimit inherited{};
  if (getrlimit(RLIMIT_AS, &inherited) == 0 && inherited.rlim_max != RLIM_INFINITY) {
    const size_t hard = size_t(inherited.rlim_max), used = virtualBytes();
    run.memoryBytes = std::min(run.memoryBytes, hard > used ? hard - used : 0);
  }
#endif
  int channel[2];
  if (pipe(channel) != 0) return run;
  std::fflush(nullptr);  // no buffered output written twice
  const pid_t pid = fork();
  if (pid < 0) {
    close(channel[0]);
    close(channel[1]);
    return run;
  }
  if (pid == 0) {
    // The child: limits, then the work. _exit: no atexit handlers, no
    // destructors of the parent's objects. Fatal signals end it as signals
    // (a sanitizer's or fuzzer's handler would turn them into exit codes).
    close(channel[0]);
    for (int fatal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) signal(fatal, SIG_DFL);
    std::set_terminate(terminateOutOfMemory);
    if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(dieAsACrash);
#if !defined(__SANITIZE_ADDRESS__)
    const size_t base = virtualBytes();
    if (base > 0) {
      const rlim_t cap = rlim_t(base + limits.memoryBytes);
      const rlimit as{cap, cap};
      if (setrlimit(RLIMIT_AS, &as) != 0) {
        // Past the hard limit the process was given (ulimit -v): all of it.
        rlimit held{};
        if (getrlimit(RLIMIT_AS, &held) == 0) {
          held.rlim_cur = held.rlim_max;
          setrlimit(RLIMIT_AS, &held);
        }
      }
    }
#endif
    const rlim_t cpu = rlim_t(std::ceil(limits.seconds));
    const rlimit cpuLimit{cpu, cpu + 1};
    setrlimit(RLIMIT_CPU, &cpuLimit);
    const rlimit noCore{0, 0};
    setrlimit(RLIMIT_CORE, &noCore);
    int code = 125;
    std::string message;
    try {
      code = work(message);
    } catch (const std::bad_alloc&) {
      code = 124;
    } catch (const std::exception& e) {
      // OpenVDB's reader wraps what it caught in its own IoError, naming
      // it: "std::bad_alloc" is an allocation that failed all the same.
      code = std::strstr(e.what(), "bad_alloc") != nullptr ? 124 : 125;
      try {
        message = e.what();
      } catch (...) {
        message.clear();
      }
    } catch (...) {
      code = 125;
    }
    const size_t n = std::min(message.size(), kIsolatedMessageBytes);
    for (size_t sent = 0; sent < n;) {
      const ssize_t w = write(channel[1], message.data() + sent, n - sent);
      if (w <= 0) break;
      sent += size_t(w);
    }
    close(channel[1]);
    _exit(code);
  }
  close(channel[1]);
  // The parent: wait, killing the child at the wall-clock limit.
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  bool killed = false;
  struct rusage usage {};
  for (auto pause = std::chrono::microseconds(200);;) {
    const pid_t done = wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (done < 0) {  // lost the child: not isolated
      close(channel[0]);
      return run;
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!killed && elapsed > limits.seconds) {
      kill(pid, SIGKILL);
      killed = true;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
  char buffer[512];
  for (ssize_t r; (r = read(channel[0], buffer, sizeof buffer)) > 0;) {
    run.message.append(buffer, size_t(r));
  }
  close(channel[0]);
  // Killed at its CPU limit, or at the wall-clock one after computing for at
  // least half of it: not a wait on a lock.
  const double cpu = double(usage.ru_utime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec) +
                     double(usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_stime.tv_usec);
  if (killed) {
    run.outcome = IsolatedRun::Outcome::TimedOut;
  } else if (WIFEXITED(status)) {
    run.exitCode = WEXITSTATUS(status);
    run.outcome = run.exitCode == 124 ? IsolatedRun::Outcome::OutOfMemory
                                      : IsolatedRun::Outcome::Finished;
  } else if (WIFSIGNALED(status)) {
    run.signal = WTERMSIG(status);
    run.outcome = run.signal == SIGXCPU || run.signal == SIGKILL
                      ? IsolatedRun::Outcome::TimedOut
                      : IsolatedRun::Outcome::Crashed;
  }
  run.usedItsCpu = run.outcome == IsolatedRun::Outcome::TimedOut &&
                   (run.signal == SIGXCPU || cpu >= 0.5 * limits.seconds);
  return run;
}

}  // namespace lo
