#include "core/resources.h"

#include <dirent.h>
#include <sys/resource.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <cstdint>

#include "core/error.h"
#include "core/printable.h"

namespace lo {

size_t peakRssBytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return size_t(usage.ru_maxrss) * 1024;  // Linux reports KiB
}

size_t currentRssBytes() {
  FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  long pages = 0, resident = 0;
  int n = std::fscanf(f, "%ld %ld", &pages, &resident);
  std::fclose(f);
  if (n != 2) return 0;
  return size_t(resident) * size_t(sysconf(_SC_PAGESIZE));
}

bool resetPeakRss() {
  FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

size_t peakRssSinceResetBytes() {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  size_t kib = 0;
  while (std::fgets(line, sizeof line, f)) {
    if (std::strncmp(line, "VmHWM:", 6) == 0) {
      kib = size_t(std::strtoull(line + 6, nullptr, 10));
      break;
    }
  }
  std::fclose(f);
  return kib * 1024;
}

StageTimer::StageTimer(std::vector<StageReport>& rows, std::string name)
    : rows_(rows), name_(std::move(name)) {}

double StageTimer::finish(std::string detail) {
  const double seconds = clock_.seconds();
  rows_.push_back({name_, seconds, currentRssBytes(), peakRssBytes(), std::move(detail)});
  return seconds;
}

void returnFreeMemory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

std::string testHook(const char* name) {
  const char* hooks = std::getenv("LIGHTOCTREE_TEST_HOOKS");
  const char* value = std::getenv(name);
  return value && hooks && std::string(hooks) == "1" ? std::string(value) : std::string();
}

std::string formatBytes(size_t bytes) {
  char buf[32];
  double b = double(bytes);
  if (b >= 1024.0 * 1024.0 * 1024.0) {
    std::snprintf(buf, sizeof buf, "%.2f GiB", b / (1024.0 * 1024.0 * 1024.0));
  } else if (b >= 1024.0 * 1024.0) {
    std::snprintf(buf, sizeof buf, "%.1f MiB", b / (1024.0 * 1024.0));
  } else {
    std::snprintf(buf, sizeof buf, "%.1f KiB", b / 1024.0);
  }
  return buf;
}

std::string formatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string formatCount(size_t n) {
  std::string s = std::to_string(n);
  for (int i = int(s.size()) - 3; i > 0; i -= 3) s.insert(size_t(i), ",");
  return s;
}

size_t memoryLimitSetting() {
  // LIGHTOCTREE_MEMORY_LIMIT: a budget of one's own, or a smaller machine's
  // in tests: bytes, or a number with K, M, G or T (binary: 2G = 2 GiB, an
  // optional "iB" or "B" after it). Anything else is refused, not ignored.
  const char* limit = std::getenv("LIGHTOCTREE_MEMORY_LIMIT");
  if (!limit) return 0;
  char* end = nullptr;
  const double number = std::strtod(limit, &end);
  double scale = 1;
  std::string unit = end ? end : "";
  if (!unit.empty()) {
    const char prefix = char(std::toupper(static_cast<unsigned char>(unit[0])));
    const std::string rest = unit.substr(1);
    const size_t power = std::string("KMGT").find(prefix);
    if (power != std::string::npos && (rest.empty() || rest == "B" || rest == "iB")) {
      scale = std::ldexp(1.0, 10 * int(power + 1));
    } else if (unit != "B") {
      scale = 0;
    }
  }
  const double bytes = number * scale;
  // Decimal only, as every flag (strtod read "0x100000000" as hexadecimal).
  const bool decimal = std::string(limit, end ? size_t(end - limit) : 0)
                           .find_first_not_of("0123456789.eE+-") == std::string::npos;
  if (end == limit || !decimal || !(bytes >= 1) || !std::isfinite(bytes) || bytes > 1e18) {
    throw InputError(std::string("LIGHTOCTREE_MEMORY_LIMIT='") + printable(limit) +
                     "': expected a size in bytes, or a number with K, M, G or T (2G: 2 GiB)");
  }
  return size_t(bytes);
}

size_t mappedBytes() {
  size_t used = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    unsigned long long pages = 0;
    if (std::fscanf(f, "%llu", &pages) == 1) used = size_t(pages) * size_t(sysconf(_SC_PAGESIZE));
    std::fclose(f);
  }
  return used;
}

namespace {

/// The threads of every process whose real user is `uid` (/proc/PID/status).
long threadsOfUser(uid_t uid) {
  long total = 0;
  DIR* proc = ::opendir("/proc");
  if (!proc) return 0;
  while (const dirent* entry = ::readdir(proc)) {
    if (!std::isdigit(static_cast<unsigned char>(entry->d_name[0]))) continue;
    const std::string status = std::string("/proc/") + entry->d_name + "/status";
    std::FILE* f = std::fopen(status.c_str(), "r");
    if (!f) continue;  // ended meanwhile, or not ours to read
    char line[256];
    long real = -1, threads = 0;
    while (std::fgets(line, sizeof line, f)) {
      std::sscanf(line, "Uid: %ld", &real);
      std::sscanf(line, "Threads: %ld", &threads);
    }
    std::fclose(f);
    if (real == long(uid)) total += threads;
  }
  ::closedir(proc);
  return total;
}

/// A number read from a cgroup file ("max" and anything else: -1).
long cgroupNumber(const char* path) {
  long value = -1;
  if (std::FILE* f = std::fopen(path, "r")) {
    if (std::fscanf(f, "%ld", &value) != 1) value = -1;
    std::fclose(f);
  }
  return value;
}

}  // namespace

long threadRoom() {
  long room = -1;
  rlimit limit{};
  if (::geteuid() != 0 && getrlimit(RLIMIT_NPROC, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    room = std::max(0L, long(limit.rlim_cur) - threadsOfUser(::getuid()));
  }
  const long most = cgroupNumber("/sys/fs/cgroup/pids.max");
  const long now = cgroupNumber("/sys/fs/cgroup/pids.current");
  if (most >= 0 && now >= 0) {
    const long left = std::max(0L, most - now);
    room = room < 0 ? left : std::min(room, left);
  }
  return room;
}

size_t addressSpaceRoomBytes() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return SIZE_MAX;
  const size_t used = mappedBytes();
  const size_t cap = size_t(limit.rlim_cur);
  return cap > used ? cap - used : 0;
}

std::string memoryShortfall() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    return "the process's address space is limited to " + formatBytes(size_t(limit.rlim_cur)) +
           " (ulimit -v), " + formatBytes(addressSpaceRoomBytes()) +
           " of it unused: raise or remove the limit";
  }
  size_t available = 0;
  try {
    available = availableMemoryBytes();
  } catch (const std::exception&) {  // a LIGHTOCTREE_MEMORY_LIMIT that is not a size
  }
  return available ? formatBytes(available) + " of memory available: give the process more"
                   : std::string("give the process more memory");
}

size_t availableMemoryBytes() {
  size_t available = 0;
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    while (std::fgets(line, sizeof line, f)) {
      unsigned long long kib = 0;
      if (std::sscanf(line, "MemAvailable: %llu kB", &kib) == 1) {
        available = size_t(kib) * 1024;
        break;
      }
    }
    std::fclose(f);
  }
  // A container's limit (cgroup v2, then v1) is what the process can have.
  for (const char* path : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    if (std::FILE* f = std::fopen(path, "r")) {
      unsigned long long limit = 0;
      const bool number = std::fscanf(f, "%llu", &limit) == 1;
      std::fclose(f);
      if (number && limit > 0 && limit < (1ull << 60)) {
        const size_t rss = currentRssBytes();
        const size_t room = size_t(limit) > rss ? size_t(limit) - rss : 0;
        available = available ? std::min(available, room) : room;
      }
      break;
    }
  }
  // An address-space limit (ulimit -v): allocations beyond it fail however
  // much memory the machine has (a bare std::bad_alloc before this cap).
  const size_t room = addressSpaceRoomBytes();
  if (room != SIZE_MAX) available = available ? std::min(available, room) : std::max<size_t>(room, 1);
  if (const size_t limit = memoryLimitSetting()) {
    available = available ? std::min(available, limit) : limit;
  }
  return available;
}

struct MemoryWatch::State {
  std::mutex mutex;
  std::condition_variable wake;
  bool stop = false;
  std::thread thread;
};

MemoryWatch::MemoryWatch(size_t limitBytes, std::function<void(size_t)> onExceeded,
                         double intervalSeconds)
    : state_(std::make_unique<State>()) {
  if (limitBytes == 0) return;
  const auto interval = std::chrono::duration<double>(std::max(intervalSeconds, 1e-3));
  State* s = state_.get();
  s->thread = std::thread([s, limitBytes, onExceeded = std::move(onExceeded), interval] {
    std::unique_lock<std::mutex> lock(s->mutex);
    while (!s->wake.wait_for(lock, interval, [s] { return s->stop; })) {
      const size_t rss = currentRssBytes();
      if (rss > limitBytes) {
        lock.unlock();
        onExceeded(rss);
        return;
      }
    }
  });
}

MemoryWatch::~MemoryWatch() {
  if (!state_ || !state_->thread.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->stop = true;
  }
  state_->wake.notify_all();
  state_->thread.join();
}

}  // namespace lo
