#include "core/file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <system_error>
#include <thread>

#include "core/error.h"
#include "core/file_set.h"
#include "core/fnv.h"
#include "core/resources.h"

namespace lo {

namespace fs = std::filesystem;

namespace file_internal {

// Temporary files alive now, removed by a signal handler if the process is
// interrupted: fixed slots of fixed size, so that the handler only reads
// memory and calls unlink (async-signal-safe).
constexpr int kSlots = 64;
constexpr size_t kPathBytes = 4096;
struct Slot {
  std::atomic<int> state{0};  // 0 free, 1 being written, 2 live
  char path[kPathBytes];
};
Slot slots[kSlots];
struct sigaction previous[3];
constexpr int kSignals[3] = {SIGINT, SIGTERM, SIGHUP};

// A set's commit in progress: a signal then waits for the renames to finish
// (raised again at the end of commit), so that a set is never left half
// renamed by SIGINT, SIGTERM or SIGHUP.
std::atomic<int> committing{0};
volatile sig_atomic_t deferredSignal = 0;

void onSignal(int sig) {
  if (committing.load() != 0) {
    deferredSignal = sig;
    return;
  }
  for (Slot& s : slots) {
    if (s.state.load() == 2) ::unlink(s.path);
  }
  for (int i = 0; i < 3; ++i) {
    if (kSignals[i] != sig) continue;
    sigaction(sig, &previous[i], nullptr);  // the handler before ours (default: terminate)
  }
  ::raise(sig);
}

void installHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int i = 0; i < 3; ++i) {
      struct sigaction current {};
      sigaction(kSignals[i], nullptr, &current);
      // An ignored signal stays ignored; a program's own handler is kept.
      if (current.sa_handler == SIG_IGN || current.sa_handler != SIG_DFL) continue;
      struct sigaction action {};
      action.sa_handler = onSignal;
      sigemptyset(&action.sa_mask);
      action.sa_flags = 0;
      sigaction(kSignals[i], &action, &previous[i]);
    }
  });
}

/// Registers `path` for removal on a signal; -1 when every slot is taken
/// (the file is still removed on errors, just not on signals).
int track(const std::string& path) {
  installHandlers();
  if (path.size() >= kPathBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(slots[i].path, path.c_str(), path.size() + 1);
      slots[i].state.store(2);
      return i;
    }
  }
  return -1;
}

void untrack(int slot) {
  if (slot >= 0) slots[slot].state.store(0);
}

std::string describe(const fs::file_status& s) {
  switch (s.type()) {
    case fs::file_type::directory: return "a folder";
    case fs::file_type::symlink: return "a symbolic link";
    case fs::file_type::block:
    case fs::file_type::character: return "a device";
    case fs::file_type::fifo: return "a pipe";
    case fs::file_type::socket: return "a socket";
    default: return "not a regular file";
  }
}

/// "" when `path` may be replaced (absent or a regular file), else why not.
std::string notReplaceable(const std::string& path) {
  std::error_code ec;
  const fs::file_status s = fs::symlink_status(path, ec);
  if (ec || s.type() == fs::file_type::not_found || s.type() == fs::file_type::regular) return "";
  return describe(s);
}

/// @throws IoError unless `path` may be replaced (absent or a regular file).
void requireReplaceable(const std::string& path) {
  const std::string refused = notReplaceable(path);
  if (!refused.empty()) {
    throw IoError(path + ": will not write: it is " + refused + " (write to a new name)");
  }
}

/// A new temporary name of `path`, its file created exclusively and without
/// following links: a name that exists (whoever put it there) is an error,
/// never something to write through. Its mode is 0666 less the umask, as
/// any new file's (0644 kept a group-writable folder's group out, umask 002).
std::string createTemporary(const std::string& path) {
  const std::string tmp = temporaryPathFor(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    throw IoError(path + ": cannot create the temporary file '" + tmp + "' (" +
                  openFailureText(errno) + ")");
  }
  ::close(fd);
  return tmp;
}

/// Fills the temporary file `tmp` of `path` with `text`.
void writeBytes(const std::string& path, const std::string& tmp, const std::string& text) {
  std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
  if (!f) throw IoError(path + ": cannot open '" + tmp + "' for writing: " + openFailureText(errno));
  f.write(text.data(), std::streamsize(text.size()));
  if (!f.flush()) throw IoError(path + ": write failed");
}

/// The inputs checkDistinctFiles and checkFolderOutputs were given, by
/// identity (device, inode) and with the thread that named them: what no
/// output may be renamed over, whatever name reaches it by then (H16-6-1).
struct WatchedInput {
  dev_t device;
  ino_t inode;
  std::string role, path;
  std::string absolute;  // path from the working folder of the check
  std::thread::id owner;
  uint64_t serial;  // in the order named (InputsWatch forgets from one on)
};
std::mutex watchedMutex;
std::vector<WatchedInput> watched;
uint64_t watchedSerial = 0;

void watchInputs(const NamedPaths& inputs) {
  const std::lock_guard<std::mutex> lock(watchedMutex);
  for (const auto& [role, path] : inputs) {
    struct stat st {};
    if (path.empty() || ::stat(path.c_str(), &st) != 0) continue;  // nothing there to replace
    std::error_code ec;
    const fs::path absolute = fs::absolute(path, ec);
    watched.push_back({st.st_dev, st.st_ino, role, path, ec ? path : absolute.string(),
                       std::this_thread::get_id(), watchedSerial++});
  }
}

/// @throws IoError when `path` (links on its way followed) is now one of the
/// watched inputs: a folder of it was replaced during the work.
void requireNotAnInput(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  const std::lock_guard<std::mutex> lock(watchedMutex);
  for (const WatchedInput& in : watched) {
    if (in.device != st.st_dev || in.inode != st.st_ino) continue;
    // Still that input under its own name: an input removed since (its
    // inode given to a new file) is no longer one.
    struct stat now {};
    if (::stat(in.absolute.c_str(), &now) == 0 && now.st_dev == in.device &&
        now.st_ino == in.inode) {
      throw IoError(path + ": will not write: it is now the input " + in.role + " ('" + in.path +
                    "'): a folder on its way was replaced during the work (a link to the "
                    "inputs' folder?); nothing written");
    }
  }
}

}  // namespace file_internal

void removeLiveTemporaries() {
  using namespace file_internal;
  // A set being renamed ends its renames first (a few system calls), as a
  // signal waits for them: the set is then whole.
  for (int i = 0; i < 1000 && committing.load() != 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (Slot& s : slots) {
    if (s.state.load() == 2) ::unlink(s.path);
  }
}

void checkPathText(const std::string& path, const std::string& name) {
  if (path.find('\0') == std::string::npos) return;
  std::string shown;
  for (char c : path) shown += c == '\0' ? std::string("\\0") : std::string(1, c);
  throw InputError(name + ": the path '" + shown +
                   "' holds a NUL byte, where the system would end it (and name another file)");
}

std::string openFailureText(int error) {
  std::string text = std::strerror(error);
  rlimit files{};
  if (error == EMFILE && getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur != RLIM_INFINITY) {
    text += " (this process may hold " + std::to_string(files.rlim_cur) +
            " at once: ulimit -n)";
  }
  return text;
}

void requireOpenable(const std::string& path) {
  checkPathText(path, "cannot open");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError("cannot open '" + path + "': " + openFailureText(errno));
  ::close(fd);
}

std::string notRegularFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return "missing";
  return fs::is_regular_file(status) ? "" : file_internal::describe(status);
}

void requireRegularFile(const std::string& path, const std::string& what) {
  checkPathText(path, what);
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw InputError(path + ": " + what + " does not exist");
  if (!fs::is_regular_file(status)) {
    throw InputError(path + ": " + what + " is " + file_internal::describe(status) +
                     " (only regular files are read)");
  }
}

std::string inputFileProblem(const std::string& path) {
  struct stat link = {};
  struct stat target = {};
  if (::lstat(path.c_str(), &link) != 0) {
    return errno == ENOENT ? "File does not exist: " + path
                           : "'" + path + "' cannot be reached: " + std::strerror(errno);
  }
  if (::stat(path.c_str(), &target) != 0) {
    if (errno == ELOOP) return "'" + path + "' is a loop of symbolic links";
    if (errno == ENOENT) return "'" + path + "' is a symbolic link to nothing";
    return "'" + path + "' cannot be reached: " + std::strerror(errno);
  }
  if (S_ISDIR(target.st_mode)) return "'" + path + "' is a folder, not a file";
  return "";
}

std::string readFile(const std::string& path) {
  checkPathText(path, "cannot read");
  // A FIFO or a device would block or never end: only regular files are read.
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw IoError("cannot read '" + path + "': no such file");
  if (!fs::is_regular_file(status)) throw IoError("cannot read '" + path + "': not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open '" + path + "': " + openFailureText(errno));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read '" + path + "': " + std::strerror(errno));
  return bytes;
}

namespace {

/// The longest file name the folder of `path` takes (NAME_MAX where pathconf
/// cannot tell).
size_t nameMaxFor(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  const long n = ::pathconf(parent.empty() ? "." : parent.c_str(), _PC_NAME_MAX);
  return n > 0 ? size_t(n) : size_t(NAME_MAX);
}

/// The bytes a temporary name adds to its prefix: ".PID-16HEX.tmp" with a
/// PID of up to 10 digits.
constexpr size_t kTemporaryTagBytes = 1 + 10 + 1 + 16 + 4;

/// The fixed head of every temporary name of `path`: ".NAME" or, when NAME
/// is too long to carry the tag within the file system's name limit, its
/// first bytes, "~" and a hash of the whole name, so that the temporary name
/// of a name the OS takes always fits too.
std::string temporaryHeadFor(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  const size_t limit = nameMaxFor(path);
  if (1 + name.size() + kTemporaryTagBytes <= limit) return "." + name;
  Fnv1a64 hash;
  hash.bytes(name.data(), name.size());
  char tail[24];
  std::snprintf(tail, sizeof tail, "~%016llx", static_cast<unsigned long long>(hash.value()));
  const size_t keep = limit > 1 + 17 + kTemporaryTagBytes + 8 ? limit - 1 - 17 - kTemporaryTagBytes : 8;
  return "." + name.substr(0, std::min(keep, name.size())) + tail;
}

}  // namespace

std::string temporaryPathFor(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  static const uint64_t seed = [] {
    std::random_device rd;
    return (uint64_t(rd()) << 32) ^ uint64_t(rd());
  }();
  const uint64_t n = counter.fetch_add(1);
  std::mt19937_64 mix(seed ^ (n * 0x9e3779b97f4a7c15ull));
  char tag[64];
  std::snprintf(tag, sizeof tag, ".%ld-%016llx.tmp", long(::getpid()),
                static_cast<unsigned long long>(mix()));
  return (fs::path(path).parent_path() / (temporaryHeadFor(path) + tag)).string();
}

bool isTemporaryPathFor(const std::string& candidate, const std::string& path) {
  const std::string name = fs::path(candidate).filename().string();
  const std::string prefix = temporaryHeadFor(path) + ".";
  return fs::path(candidate).parent_path() == fs::path(path).parent_path() &&
         name.size() > prefix.size() + 4 && name.compare(0, prefix.size(), prefix) == 0 &&
         name.compare(name.size() - 4, 4, ".tmp") == 0;
}

void checkOutputName(const std::string& path, const char* flag) {
  checkPathText(path, flag);
  const std::string name = fs::path(path).filename().string();
  const size_t limit = nameMaxFor(path);
  if (name.size() > limit) {
    throw InputError(std::string(flag) + ": the file name '" + name.substr(0, 40) + "...' is " +
                     std::to_string(name.size()) + " bytes long; the folder's file system takes " +
                     std::to_string(limit) + " (name the output shorter)");
  }
  std::error_code ec;
  const std::string absolute = fs::absolute(path, ec).string();
  if (!ec && absolute.size() + 1 > size_t(PATH_MAX)) {
    throw InputError(std::string(flag) + ": the path is " + std::to_string(absolute.size()) +
                     " bytes long; the system takes " + std::to_string(PATH_MAX - 1) +
                     " (write it to a shorter folder)");
  }
}

std::vector<std::string> leftoverTemporaries(const std::string& path) {
  std::vector<std::string> out;
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string candidate =
        (fs::path(path).parent_path() / entry.path().filename()).string();
    if (isTemporaryPathFor(candidate, path)) out.push_back(entry.path().string());
  }
  return out;
}

void writeAtomically(const std::string& path,
                     const std::function<void(const std::string& tmp)>& write) {
  // One file is a set of one: the same temporary name, checks and rename.
  AtomicFileSet set;
  set.add(path, write);
  set.commit();
}

namespace {

/// The test hook of the kill tests (tests/kill_lightmap.sh), with
/// LIGHTOCTREE_TEST_HOOKS=1: LIGHTOCTREE_PAUSE_SET=add:N pauses a set after writing its N-th file,
/// =commit after its first rename, saying so on stderr, so that a signal
/// lands at that moment every time.
void pauseForTest(const char* moment, size_t n) {
  static const std::string wanted = testHook("LIGHTOCTREE_PAUSE_SET");
  if (wanted.empty()) return;
  const std::string here = n ? std::string(moment) + ":" + std::to_string(n) : std::string(moment);
  if (wanted != here) return;
  std::fprintf(stderr, "lightoctree: paused at %s (LIGHTOCTREE_PAUSE_SET)\n", here.c_str());
  std::fflush(stderr);
  // Up to a minute, or until a signal arrives that commit defers.
  for (int i = 0; i < 1200 && file_internal::deferredSignal == 0; ++i) ::usleep(50000);
}

}  // namespace

AtomicFileSet::~AtomicFileSet() {
  for (const Entry& e : entries_) {
    if (e.committed) continue;
    std::error_code ignored;
    fs::remove(e.tmp, ignored);
    file_internal::untrack(e.slot);
  }
}

void AtomicFileSet::add(const std::string& path,
                        const std::function<void(const std::string& tmp)>& write) {
  using namespace file_internal;
  checkPathText(path, "cannot write");
  requireReplaceable(path);
  requireNotAnInput(path);
  for (const Entry& e : entries_) {
    if (e.path == path) throw IoError(path + ": named twice in one set of output files");
  }
  const std::string tmp = createTemporary(path);
  // From here the destructor removes it, whatever fails.
  entries_.push_back({path, tmp, track(tmp), 0, false});
  try {
    write(tmp);
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(path + ": cannot write (" + e.what() + ")");
  }
  if (fs::symlink_status(tmp).type() != fs::file_type::regular) {
    throw IoError(path + ": the temporary file '" + tmp + "' was replaced while writing");
  }
  std::error_code ec;
  entries_.back().bytes = uint64_t(fs::file_size(tmp, ec));
  pauseForTest("add", entries_.size());
}

void AtomicFileSet::addText(const std::string& path, const std::string& text) {
  writeOutputText(this, path, text);
}

void AtomicFileSet::commit() {
  using namespace file_internal;
  for (const Entry& e : entries_) {
    if (e.committed) continue;
    requireReplaceable(e.path);
    requireNotAnInput(e.path);
  }
  // The renames are a few system calls; a signal waits for them to end.
  struct Deferral {
    Deferral() { committing.fetch_add(1); }
    ~Deferral() {
      if (committing.fetch_sub(1) == 1 && deferredSignal != 0) {
        const int sig = deferredSignal;
        deferredSignal = 0;
        ::raise(sig);
      }
    }
  } deferral;
  for (Entry& e : entries_) {
    if (e.committed) continue;
    std::error_code ec;
    fs::rename(e.tmp, e.path, ec);
    if (ec) throw IoError(e.path + ": cannot rename '" + e.tmp + "' (" + ec.message() + ")");
    untrack(e.slot);
    e.committed = true;
    if (&e == &entries_.front()) pauseForTest("commit", 0);
  }
  for (const std::string& path : removals_) {
    std::error_code ec;
    if (fs::is_regular_file(fs::symlink_status(path, ec))) fs::remove(path, ec);
  }
  removals_.clear();
}

void AtomicFileSet::removeOnCommit(const std::string& path) {
  for (const Entry& e : entries_) {
    if (e.path == path) return;
  }
  removals_.push_back(path);
}

uint64_t AtomicFileSet::bytesOf(const std::string& path) const {
  for (const Entry& e : entries_) {
    if (e.path == path) return e.bytes;
  }
  return 0;
}

InputsWatch::~InputsWatch() {
  using namespace file_internal;
  const std::lock_guard<std::mutex> lock(watchedMutex);
  const std::thread::id self = std::this_thread::get_id();
  watched.erase(std::remove_if(watched.begin(), watched.end(),
                               [&](const WatchedInput& in) {
                                 return in.owner == self && in.serial >= first_;
                               }),
                watched.end());
}

InputsWatch::InputsWatch() {
  using namespace file_internal;
  const std::lock_guard<std::mutex> lock(watchedMutex);
  first_ = watchedSerial;
}

std::vector<std::string> AtomicFileSet::paths() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.path);
  return out;
}

void writeTextAtomically(const std::string& path, const std::string& text) {
  writeOutputText(nullptr, path, text);
}

void writeOutput(AtomicFileSet* set, const std::string& path,
                 const std::function<void(const std::string& tmp)>& write) {
  if (set) {
    set->add(path, write);
  } else {
    writeAtomically(path, write);
  }
}

void writeOutputText(AtomicFileSet* set, const std::string& path, const std::string& text) {
  writeOutput(set, path, [&](const std::string& tmp) { file_internal::writeBytes(path, tmp, text); });
}

namespace {

/// @throws InputError naming `flag` when `path` is relative and the working
/// folder it is relative to was deleted (or cannot be named): its outputs
/// would be refused only when written, after the work.
void requireWorkingFolder(const std::string& path, const char* flag) {
  if (!fs::path(path).is_relative()) return;
  std::error_code ec;
  const fs::path working = fs::current_path(ec);
  if (!ec && !working.empty()) return;
  throw InputError(std::string(flag) + ": '" + path + "' is relative to the working folder, " +
                   (ec == std::errc::no_such_file_or_directory
                        ? std::string("which was deleted")
                        : "which cannot be named (" + ec.message() + ")") +
                   ": run from a folder that exists, or give an absolute path");
}

/// @throws InputError naming `flag` unless a file can be created in `folder`
/// now: /proc, /sys and read-only mounts refuse new files whatever their
/// permission bits say (and root passes access()), which was found only when
/// the output was written, after the work. A temporary file of `path` is
/// created and removed at once.
void requireNewFileIn(const fs::path& folder, const std::string& path, const char* flag) {
  const std::string tmp = temporaryPathFor(path);
  const int slot = file_internal::track(tmp);  // removed by a signal too
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  const int error = errno;
  if (fd >= 0) {
    ::close(fd);
    ::unlink(tmp.c_str());
  }
  file_internal::untrack(slot);
  if (fd < 0) {
    throw InputError(std::string(flag) + ": folder '" + folder.string() +
                     "' takes no new file: " + std::strerror(error));
  }
}

}  // namespace

void checkOutputFolder(const std::string& path, const char* flag) {
  checkOutputName(path, flag);
  requireWorkingFolder(path, flag);
  const fs::path parent = fs::path(path).parent_path();
  const fs::path folder = parent.empty() ? fs::path(".") : parent;
  // A folder that cannot be looked up (a loop of links, one too long) is
  // said so naming the flag: std::filesystem's own text named neither.
  std::error_code ec;
  const bool isFolder = fs::is_directory(folder, ec);
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
    throw InputError(std::string(flag) + ": folder '" + folder.string() +
                     "' cannot be reached: " + ec.message() +
                     (ec == std::errc::too_many_symbolic_link_levels ? " (a loop of links?)" : ""));
  }
  if (!isFolder) {
    std::error_code ignored;
    const bool other = fs::exists(folder, ignored);
    throw InputError(std::string(flag) + ": folder '" + parent.string() +
                     (other ? "' is a file, not a folder" : "' does not exist"));
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw InputError(std::string(flag) + ": folder '" + folder.string() +
                     "' is not writable: " + std::strerror(errno));
  }
  requireNewFileIn(folder, path, flag);
  const std::string refused = file_internal::notReplaceable(path);
  if (!refused.empty()) {
    throw InputError(std::string(flag) + ": '" + path + "' is " + refused +
                     "; outputs replace only regular files (write to a new name)");
  }
}

namespace {

/// @throws InputError when `path` exists as anything but a folder (or a link to one).
void requireFolderIfPresent(const std::string& path, const char* flag) {
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);  // through links
  if (ec || s.type() == fs::file_type::not_found || s.type() == fs::file_type::directory) return;
  throw InputError(std::string(flag) + ": '" + path + "' is " +
                   (s.type() == fs::file_type::regular ? std::string("a regular file")
                                                       : file_internal::describe(s)) +
                   ", not a folder: " + flag +
                   " names the folder the files are written into (give a new name or a folder)");
}

}  // namespace

void checkResultsFolder(const std::string& path, const char* flag) {
  requireFolderIfPresent(path, flag);
  if (!fs::is_directory(path)) {
    checkOutputFolder(path, flag);  // a new folder: its parent exists and takes it
    return;
  }
  requireWorkingFolder(path, flag);
  if (::access(path.c_str(), W_OK | X_OK) != 0) {
    throw InputError(std::string(flag) + ": folder '" + path +
                     "' is not writable: " + std::strerror(errno));
  }
  requireNewFileIn(path, (fs::path(path) / "results").string(), flag);
}

void makeOutputFolder(const std::string& path, const char* flag) {
  requireFolderIfPresent(path, flag);
  std::error_code ec;
  fs::create_directories(path, ec);
  if (!fs::is_directory(path)) {
    throw InputError(std::string(flag) + ": cannot create the folder '" + path + "'" +
                     (ec ? " (" + ec.message() + ")" : ""));
  }
}

namespace {

/// `path` absolute, links and ".." resolved as far as it exists ("" for an
/// empty path, the working folder): how outputs and inputs are compared.
fs::path resolvedPath(const std::string& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path.empty() ? fs::path(".") : fs::path(path), ec);
  if (ec) return {};
  const fs::path resolved = fs::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal() : resolved;
}

}  // namespace

void checkDistinctFiles(const NamedPaths& outputs, const NamedPaths& inputs) {
  file_internal::watchInputs(inputs);
  auto same = [](const std::string& a, const std::string& b) {
    std::error_code ec1, ec2;
    if (fs::exists(a, ec1) && fs::exists(b, ec2)) {
      std::error_code ec;
      if (fs::equivalent(a, b, ec)) return true;
    }
    const fs::path ca = resolvedPath(a), cb = resolvedPath(b);
    return !ca.empty() && ca == cb;
  };
  for (size_t i = 0; i < outputs.size(); ++i) {
    const auto& [flag, path] = outputs[i];
    if (path.empty()) continue;
    for (const auto& [inFlag, in] : inputs) {
      if (!in.empty() && same(path, in)) {
        throw InputError(flag + ": '" + path + "' is the input " + inFlag +
                         ": it would be replaced; write to another name");
      }
    }
    for (size_t j = i + 1; j < outputs.size(); ++j) {
      if (!outputs[j].second.empty() && same(path, outputs[j].second)) {
        throw InputError(flag + " and " + outputs[j].first + " name the same file '" + path +
                         "'");
      }
    }
  }
}

void checkFolderOutputs(const std::string& folder,
                        const std::function<std::string(const std::string& name)>& kindOf,
                        const std::string& flag, const NamedPaths& inputs) {
  file_internal::watchInputs(inputs);
  const fs::path where = resolvedPath(folder);
  for (const auto& [role, path] : inputs) {
    if (path.empty()) continue;
    // The input as named (a link in the folder is what a write there would
    // replace) and as resolved (a link elsewhere to a file in the folder).
    const fs::path named =
        resolvedPath(fs::path(path).parent_path().string()) / fs::path(path).filename();
    for (const fs::path& in : {named, resolvedPath(path)}) {
      if (in.parent_path() != where) continue;
      const std::string kind = kindOf(in.filename().string());
      if (!kind.empty()) {
        throw InputError(flag + ": the " + kind + " would replace the input " + role + " ('" +
                         path + "'); write to another name");
      }
    }
  }
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void checkOutputFile(const std::string& path, const char* flag, const char* extension) {
  checkOutputExtension(path, flag, {extension});
  checkOutputFolder(path, flag);
}

void checkOutputExtension(const std::string& path, const char* flag,
                          std::initializer_list<const char*> extensions) {
  std::string list;
  for (const char* extension : extensions) {
    if (hasExtension(path, extension)) return;
    list += (list.empty() ? "" : " or ") + std::string(extension);
  }
  auto lower = [](std::string text) {
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return text;
  };
  const std::string name = lower(fs::path(path).filename().string());
  for (const char* extension : extensions) {
    if (name == lower(extension)) {
      throw InputError(std::string(flag) + ": '" + path + "' has no name before " + extension +
                       ": name the file (grid" + extension + ")");
    }
  }
  throw InputError(std::string(flag) + ": '" + path + "' must end in " + list);
}

bool hasExtension(const std::string& path, const char* extension) {
  std::string want(extension);
  std::transform(want.begin(), want.end(), want.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return lowerExtension(path) == want;
}

}  // namespace lo
