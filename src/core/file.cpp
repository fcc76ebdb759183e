#include "core/file.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace lo {

std::string temporaryPathFor(const std::string& path) { return path + ".tmp"; }

void writeAtomically(const std::string& path,
                     const std::function<void(const std::string& tmp)>& write) {
  const std::string tmp = temporaryPathFor(path);
  auto removeTmp = [&tmp] {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
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
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    removeTmp();
    throw IoError(path + ": cannot rename '" + tmp + "' (" + ec.message() + ")");
  }
}

void writeTextAtomically(const std::string& path, const std::string& text) {
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw IoError(path + ": cannot open '" + tmp + "' for writing");
    f.write(text.data(), std::streamsize(text.size()));
    if (!f.flush()) throw IoError(path + ": write failed");
  });
}

void checkOutputFolder(const std::string& path, const char* flag) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw InputError(std::string(flag) + ": folder '" + parent.string() + "' does not exist");
  }
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
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
