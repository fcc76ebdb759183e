/// @file scene/load_gltf.cpp
/// @brief glTF 2.0 (.gltf/.glb) loader on top of tinygltf.
///
/// tinygltf parses; the loader distrusts everything it returns. Before tinygltf
/// sees the file, external uris are confined to the scene's folder and buffer
/// views are checked against their buffers (tinygltf 2.7 indexes a buffer with
/// an unchecked bufferView when it decodes embedded images). After parsing,
/// every accessor is checked to fit its bufferView and buffer, and every index
/// to be below the vertex count, before a byte is read.
///
/// This file reads the document and runs SceneBuilder's steps in order; the
/// steps live beside it, one concern a file (gltf_internal.h lists them).

// gltf_internal.h includes tinygltf: its implementation is compiled here,
// and in no other file.
#define TINYGLTF_IMPLEMENTATION
#include "scene/gltf_internal.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/file.h"
#include "scene/gltf_prevalidate.h"

namespace lo::scene_internal {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// tinygltf callbacks.

/// Keeps the encoded bytes; images are decoded later, and only those a
/// material uses, so that the error names the problem precisely.
bool storeEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                       const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->width = image->height = image->component = image->bits = -1;
  image->as_is = true;
  return true;
}

struct FsContext {
  fs::path canonicalBase;
};

bool insideBase(const std::string& file, const FsContext& ctx) {
  std::error_code ec;
  fs::path canon = fs::weakly_canonical(file, ec);
  if (ec) return false;
  auto b = ctx.canonicalBase.begin(), f = canon.begin();
  for (; b != ctx.canonicalBase.end() && f != canon.end(); ++b, ++f) {
    if (b->empty()) continue;
    if (*b != *f) return false;
  }
  return b == ctx.canonicalBase.end();
}

// Defence in depth: the uris were checked before parsing; these refuse any
// other file too (tinygltf also looks for external files in the current
// directory, which must not happen).
bool fsFileExists(const std::string& file, void* user) {
  std::error_code ec;
  return insideBase(file, *static_cast<FsContext*>(user)) && fs::is_regular_file(file, ec);
}
std::string fsExpandFilePath(const std::string& file, void*) { return file; }
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& file,
                     void* user) {
  if (!fsFileExists(file, user)) {
    if (err) *err += "refused or missing file '" + file + "'";
    return false;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    if (err) *err += "cannot open '" + file + "'";
    return false;
  }
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}
bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                      void*) {
  if (err) *err += "the scene loader never writes files";
  return false;
}

}  // namespace

namespace gltf_internal {

Scene SceneBuilder::build() {
  for (const std::string& name : model_.extensionsUsed) {
    if (!readsGltfExtension(name)) {
      scene_.warnings.push_back(path_ + ": uses the glTF extension " + name +
                                ", which is not read: the scene is loaded without it");
    }
  }
  convertMaterials();
  decodeTextures(scene_, path_, pendingTextures_);
  pendingTextures_.clear();
  traverse();
  readSky();
  if (!skyMeshFlag_.empty()) {  // the command line's sky mesh replaces the file's sky
    skyMesh_ = skyMeshFlag_;
    turbidity_ = 0;
    scene_.sky = Sky();
    skyScale_ = false;
  }
  finishVertexAttributes();
  rebase();
  if (!skyMesh_.empty() || turbidity_ > 0) {
    // extras.lightoctree_sky, when given, scales the sky's image.
    const Vec3 scale = skyScale_ ? scene_.sky.radiance : Vec3{1, 1, 1};
    scene_.sourcePath = path_;  // for their messages
    if (!skyMesh_.empty()) {
      skyFromMaterial(scene_, skyMesh_);
    } else {
      physicalSky(scene_, turbidity_);
    }
    scene_.sky.radiance = scale;
  }
  return std::move(scene_);
}

void SceneBuilder::rebase() {
  // The sky mesh's vertices do not count: it is about to leave the scene,
  // and a sky box much larger than the site would hide how far out it lies.
  int sky = -1;
  for (size_t m = 0; m < scene_.materials.size() && !skyMesh_.empty(); ++m) {
    if (scene_.materials[m].name == skyMesh_) {
      sky = int(m);
      break;
    }
  }
  scene_internal::RebaseBounds bounds;
  for (size_t t = 0; t < scene_.triangleCount(); ++t) {
    if (scene_.triangleMaterial[t] == sky) continue;
    for (int k = 0; k < 3; ++k) bounds.extend(world_.vertices[scene_.indices[3 * t + size_t(k)]]);
  }
  const Vec3d origin = bounds.origin();
  if (origin.x == 0 && origin.y == 0 && origin.z == 0) return;
  scene_.origin = origin;
  for (size_t i = 0; i < scene_.positions.size(); ++i) {
    scene_.positions[i] = scene_.toLocal(world_.vertices[i]);
  }
  for (size_t i = 0; i < scene_.lights.size(); ++i) {
    scene_.lights[i].position = scene_.toLocal(world_.lights[i]);
  }
  for (size_t i = 0; i < scene_.cameras.size(); ++i) {
    scene_.cameras[i].position = scene_.toLocal(world_.cameras[i]);
  }
  scene_.region = Bounds3();
  for (const Vec3d& p : world_.region) scene_.region.extend(scene_.toLocal(p));
}

}  // namespace gltf_internal

Scene loadGltf(const std::string& path, const std::string& skyMesh) {
  fs::path p(path);
  std::string baseDir = p.parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  bool binary = hasExtension(path, ".glb");
  std::vector<unsigned char> bytes = readFileBytes(path, path, "file");
  if (bytes.size() > size_t(std::numeric_limits<uint32_t>::max())) {
    fail(path, "file larger than 4 GiB");
  }
  std::string jsonText = binary ? glbJson(path, bytes) : std::string(bytes.begin(), bytes.end());
  // Both JSON parsers (nlohmann here, tinygltf's copy below) recurse once per
  // level: a document nested deeper than any glTF needs would overflow the
  // stack. Counted first, outside strings.
  // UTF-16 or UTF-32 (a byte-order mark, or a zero byte in the first
  // character): the parser's error quoted the raw bytes.
  if (jsonText.size() >= 2 &&
      ((jsonText[0] == '\xff' && jsonText[1] == '\xfe') ||
       (jsonText[0] == '\xfe' && jsonText[1] == '\xff') || jsonText[0] == 0 || jsonText[1] == 0)) {
    fail(path, "invalid glTF: the JSON is UTF-16 or UTF-32 (its first bytes are a byte-order "
               "mark or hold a zero byte); glTF's JSON is UTF-8: save it as UTF-8");
  }
  checkJsonNesting(path, jsonText);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(jsonText);
  } catch (const nlohmann::json::exception& e) {
    // nlohmann's reason, without its tag ("[json.exception.parse_error.101]
    // "): the line, the column and what it read there (a number beyond a
    // double, 1e400, is as much an error as a missing comma).
    std::string reason = e.what();
    if (reason.rfind("[json.exception.", 0) == 0 && reason.find("] ") != std::string::npos) {
      reason.erase(0, reason.find("] ") + 2);
    }
    // A number overflow names the number but not where: its first place.
    const size_t quote = reason.find('\'');
    if (quote != std::string::npos && reason.find("at line") == std::string::npos) {
      const size_t at =
          jsonText.find(reason.substr(quote + 1, reason.find('\'', quote + 1) - quote - 1));
      if (at != std::string::npos) {
        const auto line = std::count(jsonText.begin(), jsonText.begin() + ptrdiff_t(at), '\n');
        const size_t lineStart = jsonText.rfind('\n', at) + 1;  // 0 on the first line
        reason += " at line " + std::to_string(line + 1) + ", column " +
                  std::to_string(at - lineStart + 1);
      }
    }
    fail(path, "invalid glTF: the JSON does not parse: " + firstLine(reason));
  }
  prevalidateJson(path, baseDir, j);
  j = nlohmann::json();

  FsContext ctx;
  std::error_code ec;
  ctx.canonicalBase = fs::weakly_canonical(baseDir, ec);
  if (ec) fail(path, "cannot resolve the scene folder '" + baseDir + "'");
  tinygltf::FsCallbacks callbacks{&fsFileExists, &fsExpandFilePath, &fsReadWholeFile,
                                  &fsWriteWholeFile, &ctx};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(callbacks);
  loader.SetImageLoader(&storeEncodedImage, nullptr);
  tinygltf::Model model;
  std::string err, warn;  // warnings are not errors: ignored
  bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                 unsigned(bytes.size()), baseDir)
                   : loader.LoadASCIIFromString(&model, &err, &warn, jsonText.data(),
                                                unsigned(jsonText.size()), baseDir);
  if (!ok) {
    std::string e = firstLine(err);
    if (e.find("File not found") != std::string::npos ||
        e.find("refused or missing") != std::string::npos) {
      fail(path, "missing buffer: " + e);
    }
    fail(path, "invalid glTF: " + (e.empty() ? std::string("tinygltf failed") : e));
  }
  bytes.clear();
  jsonText.clear();
  return gltf_internal::SceneBuilder(path, model, skyMesh).build();
}

}  // namespace lo::scene_internal
