#pragma once
/// @file core/file.h
/// @brief Reading a whole file, and output files: every writer of the project goes through these, so
/// that an interrupted or failed write never leaves a half file under the
/// final name, nothing is written through a link or over what is not a
/// regular file, and a bad output path is reported before any long work.
/// See docs/architecture.md, "Outputs".

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace lo {

/// @brief The one rule for every input file: it exists and is a regular
/// file (or a link to one). A pipe, a device or a socket would block or never
/// end, a folder cannot be read. @throws InputError "<path>: <what> is a
/// pipe (only regular files are read)", or "... does not exist".
void requireRegularFile(const std::string& path, const std::string& what);

/// Why `path` cannot be read as an input file, or "" when it can: "File does
/// not exist: PATH" (the command line parser's words), or that it is a loop
/// of symbolic links, a link to nothing, a folder, or cannot be reached (the
/// parser said "File does not exist" of each, H14-2-1).
std::string inputFileProblem(const std::string& path);

/// @brief What stands at `path` (links followed) when it is not a regular
/// file, for the message of a loader that goes on without it: "missing"
/// (nothing there, or it cannot be looked at), "a folder", "a pipe", "a
/// device", "a socket"; "" for a regular file. A texture that names a folder
/// was warned as missing.
std::string notRegularFile(const std::string& path);

/// @brief The rule for a path handed over as text (a flag, an argument of the
/// Python module): it holds no NUL byte, where the system would end it and
/// read or write another file ("out.vdb\0.png" is "out.vdb"). The readers
/// (requireRegularFile, readFile) and writers (checkOutputName, writeOutput)
/// apply it too. @throws InputError "<name>: the path 'out.vdb\0.png' holds
/// a NUL byte ...".
void checkPathText(const std::string& path, const std::string& name);

/// @brief Why an open failed, from its errno: strerror(error) and, when the
/// process holds as many files as it may (EMFILE), that limit: "Too many
/// open files (this process may hold 4 at once: ulimit -n)". Every open of
/// these functions reports it; "could not open file" hid it.
std::string openFailureText(int error);

/// @brief That `path` can be opened for reading now: for a library that
/// opens it itself and says only "could not open file" (OpenVDB), asked
/// first. @throws IoError "cannot open '<path>': <openFailureText>".
void requireOpenable(const std::string& path);

/// @brief The whole content of the file at `path`, as bytes.
/// @throws IoError naming `path` when it cannot be opened or read.
std::string readFile(const std::string& path);

/// @brief Writes `path` through a temporary file beside it: a new name per
/// call (temporaryPathFor), created exclusively (an existing file or link of
/// that name is an error, never followed), which `write(tmp)` fills and which
/// is then renamed over `path` (atomic on POSIX within one file system).
/// `path` itself is replaced only when it does not exist or is a regular file:
/// a symbolic link, a device, a folder is refused. On any failure, and on
/// SIGINT, SIGTERM or SIGHUP while the temporary file exists, it is removed;
/// an IoError names `path` and the cause; `path` is untouched.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tmp)>& write);

/// @brief writeAtomically for a text (or any byte) string.
void writeTextAtomically(const std::string& path, const std::string& text);

/// @brief A new temporary name for `path`: ".NAME.PID-RANDOM.tmp" in the same
/// folder (hidden, unpredictable, distinct for every call and process). A NAME
/// too long to carry the tag within the file system's limit on names (255
/// bytes) is cut and ends in "~" and a hash of the whole name, so a name the
/// OS takes always has a temporary name too.
std::string temporaryPathFor(const std::string& path);

/// @brief Whether `candidate` is a name temporaryPathFor(path) can return
/// (for tests that check nothing was left behind).
bool isTemporaryPathFor(const std::string& candidate, const std::string& path);

/// @brief The temporary files of `path` present in its folder.
std::vector<std::string> leftoverTemporaries(const std::string& path);

/// @throws InputError naming `flag` when `path`'s file name is longer than its
/// folder's file system takes (NAME_MAX, 255 bytes) or the whole path longer
/// than PATH_MAX: found before the work, not when the file is written.
void checkOutputName(const std::string& path, const char* flag);

/// @throws InputError naming `flag` when `path` cannot be written: its name is
/// too long (checkOutputName), its folder does not exist, is not writable or
/// takes no new file (/proc, /sys, a read-only mount, whatever its permission
/// bits say: a temporary file is created there and removed at once), a
/// relative `path`'s working folder was deleted, or `path` names a folder, a
/// link or anything but a regular file. Called by commands before any long
/// work.
void checkOutputFolder(const std::string& path, const char* flag);

/// @brief checkOutputFolder, and that `path` ends in `extension` (".vdb",
/// any case): a scene, texture or buffer named as an output was replaced by
/// a grid or a report without a word.
/// @throws InputError naming `flag`: "--output: 'scene.gltf' must end in .vdb".
void checkOutputFile(const std::string& path, const char* flag, const char* extension);

/// @brief That the file name of output `path` ends in one of `extensions`
/// (any case) and has a name before it: ".vdb" alone is, to the system, a
/// hidden name without an extension, and was refused as not ending in .vdb.
/// @throws InputError naming `flag`: "--output: 'x.obj' must end in .png or
/// .exr", "path: '.vdb' has no name before .vdb: name the file (grid.vdb)".
void checkOutputExtension(const std::string& path, const char* flag,
                          std::initializer_list<const char*> extensions);

/// @brief A folder a command writes its files into (`sweep --out`): one that
/// exists is written into, a new one is made in a folder that exists.
/// @throws InputError naming `flag` when `path` exists as anything but a
/// folder (or a link to one), "--out: 'r.md' is a regular file, not a folder:
/// --out names the folder the files are written into", when the folder is
/// not writable, or when a new one cannot be made (checkOutputFolder).
void checkResultsFolder(const std::string& path, const char* flag);

/// @brief Creates the folder `path` (and its parents) when missing.
/// @throws InputError naming `flag` and the cause when it cannot be created
/// or `path` is something other than a folder (named as checkResultsFolder
/// names it). Called by commands that write many files into one folder,
/// before any long work.
void makeOutputFolder(const std::string& path, const char* flag);

/// @brief A command's files, each with the flag that named it.
using NamedPaths = std::vector<std::pair<std::string, std::string>>;  // (flag, path)

/// @throws InputError naming both flags when an output is one of the inputs
/// (the same file, by any name) or two outputs are the same file. Empty paths
/// are skipped. Called by commands before any work. The inputs are then
/// watched: no output of the process (writeAtomically, AtomicFileSet) is
/// written over one of them, by whatever name reaches it when it is written
/// (a folder replaced meanwhile by a link to the inputs' folder, H16-6-1), until
/// the process ends or an InputsWatch of this thread ends.
void checkDistinctFiles(const NamedPaths& outputs, const NamedPaths& inputs);

/// @brief The inputs the checks of this thread name while one lives are
/// forgotten when it ends: the scope of one call in a process that makes many
/// (the Python module). A command's process keeps them to its end.
class InputsWatch {
 public:
  InputsWatch();
  ~InputsWatch();
  InputsWatch(const InputsWatch&) = delete;
  InputsWatch& operator=(const InputsWatch&) = delete;

 private:
  uint64_t first_;
};

/// @brief checkDistinctFiles for outputs named by a rule rather than listed
/// (numbered pages, saved frames, a results folder): `kindOf(name)` says what
/// the command may write under the file name `name` in `folder` ("lightmap
/// pages of 'out.glb'"; "" = nothing). Folders and inputs are compared as
/// absolute paths with links resolved, so a bare name ("out.glb" in the
/// scene's folder) is caught as surely as a full one.
/// @throws InputError "<flag>: the <kind> would replace the input <role>
/// ('<path>'); write to another name" when an input lies in `folder` under
/// such a name. Called by commands before any work; the inputs are then
/// watched as checkDistinctFiles watches them.
void checkFolderOutputs(const std::string& folder,
                        const std::function<std::string(const std::string& name)>& kindOf,
                        const std::string& flag, const NamedPaths& inputs);

/// @brief Removes every temporary output file this process has open now (those
/// a signal would remove), for a process about to end at once (_exit) from a
/// thread that cannot unwind the writers: the memory watch of the CLI.
void removeLiveTemporaries();

/// @brief True when `path` ends in `extension` (".png"), ignoring ASCII case.
bool hasExtension(const std::string& path, const char* extension);

/// @brief The extension of `path` in lower case, with its dot ("" if none).
std::string lowerExtension(const std::string& path);

}  // namespace lo
