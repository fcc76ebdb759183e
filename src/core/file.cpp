#include "core/file.h"
#include "core/file_set.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <system_error>

#include "core/error.h"

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

void onSignal(int sig) {
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
/// never something to write through.
std::string createTemporary(const std::string& path) {
  const std::string tmp = temporaryPathFor(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw IoError(path + ": cannot create the temporary file '" + tmp + "' (" +
                  std::strerror(errno) + ")");
  }
  ::close(fd);
  return tmp;
}

/// Fills the temporary file `tmp` of `path` with `text`.
void writeBytes(const std::string& path, const std::string& tmp, const std::string& text) {
  std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
  if (!f) throw IoError(path + ": cannot open '" + tmp + "' for writing");
  f.write(text.data(), std::streamsize(text.size()));
  if (!f.flush()) throw IoError(path + ": write failed");
}

}  // namespace file_internal

void requireRegularFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw InputError(path + ": " + what + " does not exist");
  if (!fs::is_regular_file(status)) {
    throw InputError(path + ": " + what + " is " + file_internal::describe(status) +
                     " (only regular files are read)");
  }
}

std::string readFile(const std::string& path) {
  // A FIFO or a device would block or never end: only regular files are read.
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw IoError("cannot read '" + path + "': no such file");
  if (!fs::is_regular_file(status)) throw IoError("cannot read '" + path + "': not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open '" + path + "': " + std::strerror(errno));
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read '" + path + "': " + std::strerror(errno));
  return bytes;
}

std::string temporaryPathFor(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  static const uint64_t seed = [] {
    std::random_device rd;
    return (uint64_t(rd()) << 32) ^ uint64_t(rd());
  }();
  const uint64_t n = counter.fetch_add(1);
  std::mt19937_64 mix(seed ^ (n * 0x9e3779b97f4a7c15ull));
  char tag[64];
  std::snprintf(tag, sizeof tag, "%ld-%016llx", long(::getpid()),
                static_cast<unsigned long long>(mix()));
  const fs::path p(path);
  return (p.parent_path() / ("." + p.filename().string() + "." + tag + ".tmp")).string();
}

bool isTemporaryPathFor(const std::string& candidate, const std::string& path) {
  const std::string name = fs::path(candidate).filename().string();
  const std::string prefix = "." + fs::path(path).filename().string() + ".";
  return fs::path(candidate).parent_path() == fs::path(path).parent_path() &&
         name.size() > prefix.size() + 4 && name.compare(0, prefix.size(), prefix) == 0 &&
         name.compare(name.size() - 4, 4, ".tmp") == 0;
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
  using namespace file_internal;
  requireReplaceable(path);
  const std::string tmp = createTemporary(path);
  const int slot = track(tmp);
  auto removeTmp = [&] {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    untrack(slot);
  };
  try {
    write(tmp);
  } catch (const IoError&) {
    removeTmp();
    throw;
  } catch (const std::exception& e) {
    removeTmp();
    throw IoError(path + ": cannot write (" + e.what() + ")");
  }
  // The writer opened the name itself: it must still be our regular file.
  if (fs::symlink_status(tmp).type() != fs::file_type::regular) {
    removeTmp();
    throw IoError(path + ": the temporary file '" + tmp + "' was replaced while writing");
  }
  const std::string refusedNow = notReplaceable(path);
  if (!refusedNow.empty()) {
    removeTmp();
    throw IoError(path + ": will not write: it is " + refusedNow + " (write to a new name)");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    removeTmp();
    throw IoError(path + ": cannot rename '" + tmp + "' (" + ec.message() + ")");
  }
  untrack(slot);
}

AtomicFileSet::~AtomicFileSet() {
  for (const Entry& e : entries_) {
    std::error_code ignored;
    fs::remove(e.tmp, ignored);
    file_internal::untrack(e.slot);
  }
}

void AtomicFileSet::add(const std::string& path,
                        const std::function<void(const std::string& tmp)>& write) {
  using namespace file_internal;
  requireReplaceable(path);
  for (const Entry& e : entries_) {
    if (e.path == path) throw IoError(path + ": named twice in one set of output files");
  }
  const std::string tmp = createTemporary(path);
  // From here the destructor removes it, whatever fails.
  entries_.push_back({path, tmp, track(tmp)});
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
}

void AtomicFileSet::addText(const std::string& path, const std::string& text) {
  add(path, [&](const std::string& tmp) { file_internal::writeBytes(path, tmp, text); });
}

void AtomicFileSet::commit() {
  using namespace file_internal;
  for (const Entry& e : entries_) requireReplaceable(e.path);
  while (!entries_.empty()) {
    const Entry e = entries_.front();
    std::error_code ec;
    fs::rename(e.tmp, e.path, ec);
    if (ec) throw IoError(e.path + ": cannot rename '" + e.tmp + "' (" + ec.message() + ")");
    untrack(e.slot);
    entries_.erase(entries_.begin());
  }
}

std::vector<std::string> AtomicFileSet::paths() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.path);
  return out;
}

void writeTextAtomically(const std::string& path, const std::string& text) {
  writeAtomically(path,
                  [&](const std::string& tmp) { file_internal::writeBytes(path, tmp, text); });
}

void checkOutputFolder(const std::string& path, const char* flag) {
  const fs::path parent = fs::path(path).parent_path();
  const fs::path folder = parent.empty() ? fs::path(".") : parent;
  if (!fs::is_directory(folder)) {
    throw InputError(std::string(flag) + ": folder '" + parent.string() + "' does not exist");
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw InputError(std::string(flag) + ": folder '" + folder.string() +
                     "' is not writable: " + std::strerror(errno));
  }
  const std::string refused = file_internal::notReplaceable(path);
  if (!refused.empty()) {
    throw InputError(std::string(flag) + ": '" + path + "' is " + refused +
                     "; outputs replace only regular files (write to a new name)");
  }
}

void makeOutputFolder(const std::string& path, const char* flag) {
  std::error_code ec;
  fs::create_directories(path, ec);
  if (!fs::is_directory(path)) {
    throw InputError(std::string(flag) + ": cannot create the folder '" + path + "'" +
                     (ec ? " (" + ec.message() + ")" : ""));
  }
}

void checkDistinctFiles(const NamedPaths& outputs, const NamedPaths& inputs) {
  auto same = [](const std::string& a, const std::string& b) {
    std::error_code ec1, ec2;
    if (fs::exists(a, ec1) && fs::exists(b, ec2)) {
      std::error_code ec;
      if (fs::equivalent(a, b, ec)) return true;
    }
    std::error_code ea, eb;
    const fs::path ca = fs::weakly_canonical(a, ea), cb = fs::weakly_canonical(b, eb);
    return !ea && !eb && ca == cb;
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

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

bool hasExtension(const std::string& path, const char* extension) {
  std::string want(extension);
  std::transform(want.begin(), want.end(), want.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return lowerExtension(path) == want;
}

}  // namespace lo
