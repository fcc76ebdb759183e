#pragma once
/// @file core/file.h
/// @brief Output files: every writer of the project goes through these, so
/// that an interrupted or failed write never leaves a half file under the
/// final name, and a bad output path is reported before any long work.

#include <functional>
#include <string>

namespace lo {

/// @brief Writes `path` through a temporary file beside it: `write(tmp)` fills
/// the temporary file, which is then renamed over `path` (atomic on POSIX
/// within one file system). On any failure the temporary file is removed and
/// an IoError naming `path` and the cause is thrown; `path` is untouched.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tmp)>& write);

/// @brief writeAtomically for a text (or any byte) string.
void writeTextAtomically(const std::string& path, const std::string& text);

/// @brief The temporary name writeAtomically uses for `path`.
std::string temporaryPathFor(const std::string& path);

/// @throws InputError naming `flag` when the folder that would hold `path`
/// does not exist. Called by commands before any long work.
void checkOutputFolder(const std::string& path, const char* flag);

/// @brief True when `path` ends in `extension` (".png"), ignoring ASCII case.
bool hasExtension(const std::string& path, const char* extension);

/// @brief The extension of `path` in lower case, with its dot ("" if none).
std::string lowerExtension(const std::string& path);

}  // namespace lo
