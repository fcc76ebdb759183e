#pragma once
// The loaders take paths and pick the format by extension: each fuzz input
// is written to one file per process (in TMPDIR) with the extension, then
// loaded. Only lo::InputError may escape a loader; anything else is a finding.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace lo::fuzz {

inline std::string inputPath(const char* extension) {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir && *dir ? dir : "/tmp") + "/lightoctree-fuzz-" +
         std::to_string(getpid()) + extension;
}

inline void writeInput(const std::string& path, const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

}  // namespace lo::fuzz
