#pragma once
/// @file tools/text_file.h
/// @brief Small file helpers of the front end: atomic text writes and output
/// folder checks done before any long work.

#include <string>

namespace lo::tool {

/// Writes `text` to `path` through `path.tmp` and a rename. @throws IoError naming the file.
void writeTextAtomically(const std::string& path, const std::string& text);

/// @throws InputError naming `flag` when the folder that would hold `path` does not exist.
void checkOutputFolder(const std::string& path, const char* flag);

}  // namespace lo::tool
