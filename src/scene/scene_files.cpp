#include "scene/scene_files.h"

#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.h"
#include "core/file.h"
#include "core/fnv.h"
#include "scene/gltf_prevalidate.h"
#include "scene/scene_internal.h"

namespace lo {
namespace {

namespace fs = std::filesystem;
using namespace scene_internal;

/// The uris of `key` (buffers or images) that name files.
void addUris(const std::string& path, const std::string& baseDir, const nlohmann::json& j,
             const char* key, std::vector<std::string>& out) {
  auto list = j.find(key);
  if (list == j.end() || !list->is_array()) return;
  for (const nlohmann::json& item : *list) {
    if (!item.is_object()) continue;
    auto uri = item.find("uri");
    if (uri == item.end() || !uri->is_string()) continue;
    const std::string u = uri->get<std::string>();
    if (u.rfind("data:", 0) == 0) continue;
    try {
      out.push_back(resolveInsideFolder(path, baseDir, percentDecode(u), key));
    } catch (const InputError&) {
      // Outside the folder: the load refuses the scene.
    }
  }
}

/// The JSON of a .gltf, or of a .glb's first chunk (read alone: the
/// binary chunk after it may be large). Empty when the file is not one.
std::string gltfJson(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!hasExtension(path, ".glb")) {
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }
  unsigned char header[20];
  if (!in.read(reinterpret_cast<char*>(header), sizeof header)) return "";
  const uint32_t jsonLength = uint32_t(header[12]) | uint32_t(header[13]) << 8 |
                              uint32_t(header[14]) << 16 | uint32_t(header[15]) << 24;
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec || std::memcmp(header, "glTF", 4) != 0 || 20 + uintmax_t(jsonLength) > size) return "";
  std::string text(jsonLength, '\0');
  if (!in.read(text.data(), std::streamsize(jsonLength))) return "";
  return text;
}

void gltfFiles(const std::string& path, const std::string& baseDir,
               std::vector<std::string>& out) {
  const std::string text = gltfJson(path);
  checkJsonNesting(path, text);
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return;
  addUris(path, baseDir, j, "buffers", out);
  addUris(path, baseDir, j, "images", out);
  // The sky image a scene's extras name (loadScene reads it too).
  auto scenes = j.find("scenes");
  if (scenes == j.end() || !scenes->is_array()) return;
  for (const nlohmann::json& scene : *scenes) {
    if (!scene.is_object() || !scene.contains("extras") || !scene["extras"].is_object()) continue;
    auto sky = scene["extras"].find("lightoctree_sky_image");
    if (sky == scene["extras"].end() || !sky->is_string()) continue;
    try {
      out.push_back(resolveInsideFolder(path, baseDir, sky->get<std::string>(), "sky image"));
    } catch (const InputError&) {
    }
  }
}

/// The whitespace-separated words of `line` after its first.
std::vector<std::string> wordsAfterFirst(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  std::string w;
  in >> w;
  while (in >> w) words.push_back(w);
  return words;
}

void objFiles(const std::string& path, const std::string& baseDir, std::vector<std::string>& out) {
  std::ifstream obj(path);
  skipByteOrderMark(obj);
  std::string line;
  std::vector<std::string> libraries;
  while (std::getline(obj, line)) {
    if (line.rfind("mtllib", 0) != 0) continue;
    for (const std::string& name : wordsAfterFirst(line)) {
      try {
        libraries.push_back(resolveInsideFolder(path, baseDir, name, "mtllib"));
      } catch (const InputError&) {
      }
    }
  }
  for (const std::string& library : libraries) {
    out.push_back(library);
    std::ifstream mtl(library);
    skipByteOrderMark(mtl);
    while (std::getline(mtl, line)) {
      const size_t start = line.find_first_not_of(" \t");
      if (start == std::string::npos || line.compare(start, 6, "map_Kd") != 0) continue;
      const std::vector<std::string> words = wordsAfterFirst(line.substr(start));
      if (words.empty()) continue;
      try {
        out.push_back(resolveInsideFolder(path, baseDir, words.back(), "map_Kd"));
      } catch (const InputError&) {
      }
    }
  }
}

}  // namespace

std::vector<std::string> sceneFiles(const std::string& path) {
  std::vector<std::string> files{path};
  std::string baseDir = fs::path(path).parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  try {
    requireRegularFile(path, "scene");  // a FIFO would hang the reads below
    if (hasExtension(path, ".obj")) {
      objFiles(path, baseDir, files);
    } else {
      gltfFiles(path, baseDir, files);
    }
  } catch (const InputError&) {
    // The load says what is wrong with the file.
  }
  std::vector<std::string> unique;
  for (const std::string& f : files) {
    if (std::find(unique.begin(), unique.end(), f) == unique.end()) unique.push_back(f);
  }
  return unique;
}

std::string sceneFilesStamp(const std::vector<std::string>& files) {
  std::string stamp;
  for (const std::string& file : files) {
    struct stat st {};
    char text[160];
    if (::stat(file.c_str(), &st) != 0) {
      std::snprintf(text, sizeof text, "missing\n");
    } else {
      std::snprintf(text, sizeof text, "%llu %llu %lld %lld.%09ld %lld.%09ld\n",
                    static_cast<unsigned long long>(st.st_dev),
                    static_cast<unsigned long long>(st.st_ino), static_cast<long long>(st.st_size),
                    static_cast<long long>(st.st_mtim.tv_sec), st.st_mtim.tv_nsec,
                    static_cast<long long>(st.st_ctim.tv_sec), st.st_ctim.tv_nsec);
    }
    stamp += text;
  }
  return stamp;
}

std::string sceneContentHash(const std::string& path) {
  return sceneContentHash(path, sceneFiles(path));
}

std::string sceneContentHash(const std::string& path, const std::vector<std::string>& files) {
  Fnv1a64 hash;
  auto add = [&hash](const void* data, size_t size) { hash.bytes(data, size); };
  const fs::path folder = fs::path(path).parent_path();
  std::vector<char> buffer(1 << 16);
  bool first = true;
  for (const std::string& file : files) {
    // The files it reads by name, but not the scene's own name: a renamed
    // copy is the same scene.
    std::error_code ec;
    std::string name = fs::relative(file, folder.empty() ? fs::path(".") : folder, ec).generic_string();
    if (ec || name.empty()) name = fs::path(file).filename().string();
    if (first) name.clear();
    first = false;
    add(name.data(), name.size() + 1);  // with its terminating zero
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      add("missing", 7);
      continue;
    }
    uint64_t size = 0;
    while (in) {
      in.read(buffer.data(), std::streamsize(buffer.size()));
      const size_t got = size_t(in.gcount());
      add(buffer.data(), got);
      size += got;
    }
    add(&size, sizeof size);
  }
  char text[32];
  std::snprintf(text, sizeof text, "fnv1a64:%016llx", static_cast<unsigned long long>(hash.value()));
  return text;
}

}  // namespace lo
