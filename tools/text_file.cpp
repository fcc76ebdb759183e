#include "text_file.h"

#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace lo::tool {

void writeTextAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw IoError(path + ": cannot open for writing");
    f << text;
    if (!f.flush()) {
      f.close();
      std::filesystem::remove(tmp);
      throw IoError(path + ": write failed");
    }
  }
  std::filesystem::rename(tmp, path);
}

void checkOutputFolder(const std::string& path, const char* flag) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw InputError(std::string(flag) + ": folder '" + parent.string() + "' does not exist");
  }
}

}  // namespace lo::tool
