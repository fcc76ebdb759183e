#pragma once
/// @file core/file_set.h
/// @brief Several output files that appear together or not at all (a
/// lightmap's glTF, buffer, pages and preview): each is written under its
/// temporary name with writeAtomically's rules (created exclusively, no link
/// followed, a link or device at the final name refused), and commit()
/// renames them all at the end. A set that fails, or is destroyed without
/// commit(), removes its temporaries (on SIGINT, SIGTERM and SIGHUP too):
/// files left by an earlier run under the final names stay as they were.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace lo {

class AtomicFileSet {
 public:
  AtomicFileSet() = default;
  ~AtomicFileSet();
  AtomicFileSet(const AtomicFileSet&) = delete;
  AtomicFileSet& operator=(const AtomicFileSet&) = delete;

  /// Writes `path`'s content to its temporary file through `write(tmp)`.
  /// @throws IoError naming `path` (refused final name, a name given twice,
  /// a failed write); the set's other files are then still uncommitted.
  void add(const std::string& path, const std::function<void(const std::string& tmp)>& write);
  void addText(const std::string& path, const std::string& text);
  /// Also removes `path` (a file an earlier set had that this one replaces
  /// with nothing: a page beyond its page count) at commit, after the
  /// renames and with them: a signal waits for both. Not a file in the set;
  /// a link or anything but a regular file there is left alone.
  void removeOnCommit(const std::string& path);
  /// Checks every final name once more, then renames every temporary over
  /// it, then removes the removeOnCommit files.
  /// @throws IoError when a name became a link or a device meanwhile (nothing
  /// renamed) or a rename fails (the files renamed before it stay).
  void commit();
  /// The final names, in the order added (committed or not).
  std::vector<std::string> paths() const;
  /// The bytes written for `path` (0 when it is not in the set).
  uint64_t bytesOf(const std::string& path) const;

 private:
  struct Entry {
    std::string path, tmp;
    int slot;
    uint64_t bytes;
    bool committed;
  };
  std::vector<Entry> entries_;
  std::vector<std::string> removals_;
};

/// Writes `path` through `write(tmp)`: into `set` when one is given (renamed
/// with the others by its commit), else on its own (writeAtomically). The
/// writers that may be part of a set (images, .vdb files) take this path.
void writeOutput(AtomicFileSet* set, const std::string& path,
                 const std::function<void(const std::string& tmp)>& write);
/// writeOutput of a byte string.
void writeOutputText(AtomicFileSet* set, const std::string& path, const std::string& text);

}  // namespace lo
