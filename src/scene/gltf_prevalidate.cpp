// Checks on a glTF's raw JSON and GLB container, before tinygltf
// dereferences anything (load_gltf.cpp calls them first): nesting depth,
// integers tinygltf would wrap, buffers and buffer views that fit, external
// files confined to the scene's folder.

#include "scene/gltf_prevalidate.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/printable.h"
#include "scene/scene_internal.h"

namespace lo::scene_internal {

namespace fs = std::filesystem;

static bool isDataUri(const std::string& uri) { return uri.rfind("data:", 0) == 0; }

/// The bytes a base64 data URI decodes to, as tinygltf's base64_decode
/// decodes it (the base64 characters up to the first other one, '='
/// included); -1 for a data URI that is not base64.
static int64_t dataUriBytes(const std::string& uri) {
  const size_t comma = uri.find(',');
  if (comma == std::string::npos || comma < 7 || uri.compare(comma - 7, 7, ";base64") != 0) {
    return -1;
  }
  int64_t chars = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i, ++chars) {
    const unsigned char c = static_cast<unsigned char>(uri[i]);
    if (!(std::isalnum(c) || c == '+' || c == '/')) break;
  }
  return 3 * (chars / 4) + (chars % 4 > 0 ? chars % 4 - 1 : 0);
}

static uint64_t jsonUInt(const nlohmann::json& o, const char* key, uint64_t fallback) {
  auto it = o.find(key);
  if (it == o.end() || !it->is_number_unsigned()) return fallback;
  return it->get<uint64_t>();
}

void checkJsonNesting(const std::string& path, const std::string& text) {
  size_t depth = 0;
  bool inString = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') {
        ++i;  // the escaped character
      } else if (c == '"') {
        inString = false;
      }
    } else if (c == '"') {
      inString = true;
    } else if (c == '{' || c == '[') {
      if (++depth > kMaxJsonDepth) {
        fail(path, "invalid glTF: JSON nested more than " + std::to_string(kMaxJsonDepth) +
                       " levels deep (at byte " + std::to_string(i) + ")");
      }
    } else if ((c == '}' || c == ']') && depth > 0) {
      --depth;
    }
  }
}

/// Integers the glTF gives where tinygltf keeps an int (indices, enums):
/// beyond int32 they would wrap (2^32 + 3 read as 3, a silently wrong
/// scene). Sizes (byteLength, byteOffset, count) are 64-bit in tinygltf.
static void checkIntegerRanges(const std::string& path, const nlohmann::json& j,
                        const std::string& where, int depth) {
  if (depth > int(kMaxJsonDepth)) return;
  auto check = [&](const std::string& key, const nlohmann::json& v, const std::string& at) {
    if (!v.is_number_integer() || key == "byteLength" || key == "byteOffset" || key == "count") {
      checkIntegerRanges(path, v, at, depth + 1);
      return;
    }
    const bool fits = v.is_number_unsigned()
                          ? v.get<uint64_t>() <= uint64_t(std::numeric_limits<int32_t>::max())
                          : v.get<int64_t>() >= std::numeric_limits<int32_t>::min() &&
                                v.get<int64_t>() <= std::numeric_limits<int32_t>::max();
    if (!fits) fail(path, "invalid glTF: " + at + " = " + v.dump() + " is out of range");
  };
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) check(it.key(), it.value(), where + "/" + it.key());
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) check("", j[i], where + "/" + std::to_string(i));
  }
}

namespace {

/// What a field the loader reads must hold: tinygltf takes a field of
/// another type (an intensity "5", an emissiveFactor "bright") for absent
/// and gives its default without a word.
struct FieldRule {
  const char* pointer;  ///< JSON pointer; "*" stands for every element of an array or member of an object
  enum Kind { kNumber, kNumbers, kString, kStrings, kBool, kObject, kArray, kIndex, kIndices } kind;
  size_t count = 0;  ///< kNumbers: how many (0: any); kArray: at least how many elements
  bool required = false;  ///< glTF requires it where its parent is (a primitive's attributes)
};

const FieldRule kFieldRules[] = {
    {"/asset", FieldRule::kObject},
    {"/asset/version", FieldRule::kString},
    {"/asset/minVersion", FieldRule::kString},
    {"/scene", FieldRule::kIndex},
    {"/extensionsUsed", FieldRule::kStrings},
    {"/extensionsRequired", FieldRule::kStrings},
    // Every element of the file's arrays is an object (a null primitive or
    // node was dropped without a word).
    {"/scenes/*", FieldRule::kObject},
    {"/nodes/*", FieldRule::kObject},
    {"/meshes/*", FieldRule::kObject},
    {"/materials/*", FieldRule::kObject},
    {"/textures/*", FieldRule::kObject},
    {"/images/*", FieldRule::kObject},
    {"/samplers/*", FieldRule::kObject},
    {"/accessors/*", FieldRule::kObject},
    {"/bufferViews/*", FieldRule::kObject},
    {"/buffers/*", FieldRule::kObject},
    {"/cameras/*", FieldRule::kObject},
    {"/materials/*/name", FieldRule::kString},
    {"/materials/*/emissiveFactor", FieldRule::kNumbers, 3},
    {"/materials/*/alphaMode", FieldRule::kString},
    {"/materials/*/alphaCutoff", FieldRule::kNumber},
    {"/materials/*/doubleSided", FieldRule::kBool},
    {"/materials/*/pbrMetallicRoughness", FieldRule::kObject},
    {"/materials/*/pbrMetallicRoughness/baseColorFactor", FieldRule::kNumbers, 4},
    {"/materials/*/pbrMetallicRoughness/metallicFactor", FieldRule::kNumber},
    {"/materials/*/pbrMetallicRoughness/roughnessFactor", FieldRule::kNumber},
    {"/materials/*/extensions/KHR_materials_unlit", FieldRule::kObject},
    {"/materials/*/normalTexture/scale", FieldRule::kNumber},
    {"/materials/*/occlusionTexture/strength", FieldRule::kNumber},
    {"/materials/*/extensions/KHR_materials_emissive_strength/emissiveStrength",
     FieldRule::kNumber},
    {"/materials/*/extensions/KHR_materials_ior/ior", FieldRule::kNumber},
    {"/materials/*/extensions/KHR_materials_transmission/transmissionFactor", FieldRule::kNumber},
    {"/materials/*/extensions/KHR_materials_specular/specularFactor", FieldRule::kNumber},
    {"/materials/*/extensions/KHR_materials_volume/thicknessFactor", FieldRule::kNumber},
    {"/extensions/KHR_lights_punctual/lights", FieldRule::kArray},
    {"/extensions/KHR_lights_punctual/lights/*", FieldRule::kObject},
    {"/nodes/*/extensions/KHR_lights_punctual/light", FieldRule::kIndex, 0, true},
    {"/extensions/KHR_lights_punctual/lights/*/name", FieldRule::kString},
    {"/extensions/KHR_lights_punctual/lights/*/type", FieldRule::kString},
    {"/extensions/KHR_lights_punctual/lights/*/color", FieldRule::kNumbers, 3},
    {"/extensions/KHR_lights_punctual/lights/*/intensity", FieldRule::kNumber},
    {"/extensions/KHR_lights_punctual/lights/*/range", FieldRule::kNumber},
    {"/extensions/KHR_lights_punctual/lights/*/spot", FieldRule::kObject},
    {"/extensions/KHR_lights_punctual/lights/*/spot/innerConeAngle", FieldRule::kNumber},
    {"/extensions/KHR_lights_punctual/lights/*/spot/outerConeAngle", FieldRule::kNumber},
    {"/nodes/*/name", FieldRule::kString},
    {"/nodes/*/matrix", FieldRule::kNumbers, 16},
    {"/nodes/*/translation", FieldRule::kNumbers, 3},
    {"/nodes/*/rotation", FieldRule::kNumbers, 4},
    {"/nodes/*/scale", FieldRule::kNumbers, 3},
    {"/cameras/*/type", FieldRule::kString},
    {"/cameras/*/perspective/yfov", FieldRule::kNumber},
    {"/cameras/*/perspective/aspectRatio", FieldRule::kNumber},
    {"/cameras/*/perspective/znear", FieldRule::kNumber},
    {"/cameras/*/perspective/zfar", FieldRule::kNumber},
    {"/cameras/*/orthographic/xmag", FieldRule::kNumber},
    {"/cameras/*/orthographic/ymag", FieldRule::kNumber},
    {"/cameras/*/orthographic/znear", FieldRule::kNumber},
    {"/cameras/*/orthographic/zfar", FieldRule::kNumber},
    // What ties the file together: an index of another type, or -1, made
    // tinygltf drop the node's mesh, a subtree or an accessor's offset.
    {"/scenes/*/nodes", FieldRule::kIndices},
    {"/nodes/*/children", FieldRule::kIndices},
    {"/nodes/*/mesh", FieldRule::kIndex},
    {"/nodes/*/camera", FieldRule::kIndex},
    {"/meshes/*/primitives", FieldRule::kArray, 1},
    {"/meshes/*/primitives/*", FieldRule::kObject},
    {"/meshes/*/primitives/*/attributes", FieldRule::kObject, 0, true},
    {"/meshes/*/primitives/*/attributes/*", FieldRule::kIndex},
    {"/meshes/*/primitives/*/indices", FieldRule::kIndex},
    {"/meshes/*/primitives/*/material", FieldRule::kIndex},
    {"/meshes/*/primitives/*/mode", FieldRule::kIndex},
    // Morph targets and their weights (strings or an object of weights were
    // taken as none, H15-4-1).
    {"/meshes/*/primitives/*/targets", FieldRule::kArray},
    {"/meshes/*/primitives/*/targets/*", FieldRule::kObject},
    {"/meshes/*/primitives/*/targets/*/*", FieldRule::kIndex},
    {"/meshes/*/weights", FieldRule::kNumbers},
    {"/nodes/*/weights", FieldRule::kNumbers},
    {"/accessors/*/bufferView", FieldRule::kIndex},
    {"/accessors/*/byteOffset", FieldRule::kIndex},
    {"/accessors/*/count", FieldRule::kIndex, 0, true},
    {"/accessors/*/componentType", FieldRule::kIndex, 0, true},
    {"/accessors/*/type", FieldRule::kString, 0, true},
    {"/bufferViews/*/buffer", FieldRule::kIndex, 0, true},
    {"/bufferViews/*/byteOffset", FieldRule::kIndex},
    {"/bufferViews/*/byteLength", FieldRule::kIndex, 0, true},
    {"/bufferViews/*/byteStride", FieldRule::kIndex},
    {"/buffers/*/byteLength", FieldRule::kIndex, 0, true},
    {"/buffers/*/uri", FieldRule::kString},
    {"/images/*/uri", FieldRule::kString},
    {"/images/*/mimeType", FieldRule::kString},
    {"/images/*/bufferView", FieldRule::kIndex},
    {"/textures/*/source", FieldRule::kIndex},
    {"/textures/*/sampler", FieldRule::kIndex},
    {"/samplers/*/magFilter", FieldRule::kIndex},
    {"/samplers/*/minFilter", FieldRule::kIndex},
    {"/samplers/*/wrapS", FieldRule::kIndex},
    {"/samplers/*/wrapT", FieldRule::kIndex},
    // A material's textures: an index "0" dropped the texture.
    {"/materials/*/pbrMetallicRoughness/baseColorTexture", FieldRule::kObject},
    {"/materials/*/pbrMetallicRoughness/baseColorTexture/index", FieldRule::kIndex, 0, true},
    {"/materials/*/pbrMetallicRoughness/baseColorTexture/texCoord", FieldRule::kIndex},
    {"/materials/*/pbrMetallicRoughness/metallicRoughnessTexture", FieldRule::kObject},
    {"/materials/*/pbrMetallicRoughness/metallicRoughnessTexture/index", FieldRule::kIndex, 0, true},
    {"/materials/*/pbrMetallicRoughness/metallicRoughnessTexture/texCoord", FieldRule::kIndex},
    {"/materials/*/normalTexture", FieldRule::kObject},
    {"/materials/*/normalTexture/index", FieldRule::kIndex, 0, true},
    {"/materials/*/normalTexture/texCoord", FieldRule::kIndex},
    {"/materials/*/occlusionTexture", FieldRule::kObject},
    {"/materials/*/occlusionTexture/index", FieldRule::kIndex, 0, true},
    {"/materials/*/occlusionTexture/texCoord", FieldRule::kIndex},
    {"/materials/*/emissiveTexture", FieldRule::kObject},
    {"/materials/*/emissiveTexture/index", FieldRule::kIndex, 0, true},
    {"/materials/*/emissiveTexture/texCoord", FieldRule::kIndex},
    {"/materials/*/extensions/KHR_materials_transmission/transmissionTexture/index",
     FieldRule::kIndex},
    {"/materials/*/extensions/KHR_materials_volume/thicknessTexture/index", FieldRule::kIndex},
    {"/materials/*/extensions/KHR_materials_specular/specularTexture/index", FieldRule::kIndex},
    {"/materials/*/extensions/KHR_materials_specular/specularColorTexture/index",
     FieldRule::kIndex},
};

/// A whole number from 0 written as an integer (tinygltf drops 5.0 too).
bool isIndex(const nlohmann::json& v) {
  if (v.is_number_unsigned()) return true;
  return v.is_number_integer() && v.get<int64_t>() >= 0;
}

bool holds(const nlohmann::json& v, const FieldRule& rule) {
  switch (rule.kind) {
    case FieldRule::kNumber: return v.is_number();
    case FieldRule::kString: return v.is_string();
    case FieldRule::kBool: return v.is_boolean();
    case FieldRule::kObject: return v.is_object();
    case FieldRule::kArray: return v.is_array() && v.size() >= rule.count;
    case FieldRule::kStrings:
      if (!v.is_array()) return false;
      for (const nlohmann::json& x : v) {
        if (!x.is_string()) return false;
      }
      return true;
    case FieldRule::kIndex: return isIndex(v);
    case FieldRule::kIndices:
      if (!v.is_array()) return false;
      for (const nlohmann::json& x : v) {
        if (!isIndex(x)) return false;
      }
      return true;
    case FieldRule::kNumbers:
      if (!v.is_array() || (rule.count > 0 && v.size() != rule.count)) return false;
      for (const nlohmann::json& x : v) {
        if (!x.is_number()) return false;
      }
      return true;
  }
  return false;
}

std::string expected(const FieldRule& rule) {
  switch (rule.kind) {
    case FieldRule::kNumber: return "a number";
    case FieldRule::kString: return "a string";
    case FieldRule::kBool: return "true or false";
    case FieldRule::kObject: return "an object";
    case FieldRule::kArray:
      return rule.count > 0 ? "an array of at least " + std::to_string(rule.count) + " element" +
                                  (rule.count > 1 ? "s" : "")
                            : "an array";
    case FieldRule::kStrings: return "an array of strings";
    case FieldRule::kIndex: return "a whole number from 0 (an integer)";
    case FieldRule::kIndices: return "an array of whole numbers from 0 (integers)";
    case FieldRule::kNumbers:
      return rule.count > 0 ? "an array of " + std::to_string(rule.count) + " numbers"
                            : "an array of numbers";
  }
  return "";
}

/// Checks `rule` from `at` (the pointer's parts from `part` on) in `j`, whose
/// own pointer is `where`.
void checkField(const std::string& path, const nlohmann::json& j, const FieldRule& rule,
                const std::vector<std::string>& parts, size_t part, const std::string& where) {
  if (part == parts.size()) {
    if (holds(j, rule)) return;
    std::string shown = j.dump();
    if (shown.size() > 60) shown = shown.substr(0, 60) + "...";
    fail(path, "invalid glTF: " + where + " is " + printable(shown) + ", expected " +
                   expected(rule));
  }
  const std::string& key = parts[part];
  if (key == "*") {
    if (j.is_object()) {  // every member of an object (a primitive's attributes)
      for (auto it = j.begin(); it != j.end(); ++it) {
        checkField(path, it.value(), rule, parts, part + 1, where + "/" + it.key());
      }
      return;
    }
    if (!j.is_array()) return;
    for (size_t i = 0; i < j.size(); ++i) {
      checkField(path, j[i], rule, parts, part + 1, where + "/" + std::to_string(i));
    }
    return;
  }
  if (!j.is_object()) return;
  auto it = j.find(key);
  if (it != j.end()) {
    checkField(path, *it, rule, parts, part + 1, where + "/" + key);
  } else if (rule.required && part + 1 == parts.size()) {
    // A primitive without attributes was dropped, a texture without an index
    // read as none, without a word (H12-4-23, -167).
    fail(path, "invalid glTF: " + where + "/" + key + " is missing, expected " + expected(rule));
  }
}

}  // namespace

void checkFieldTypes(const std::string& path, const nlohmann::json& j) {
  for (const FieldRule& rule : kFieldRules) {
    std::vector<std::string> parts;
    std::string pointer = rule.pointer;
    for (size_t at = 1, next; at <= pointer.size(); at = next + 1) {
      next = pointer.find('/', at);
      if (next == std::string::npos) next = pointer.size();
      parts.push_back(pointer.substr(at, next - at));
    }
    checkField(path, j, rule, parts, 0, "");
  }
  // The project's keys are read from the scene's extras (docs/scene.md): in
  // the file's own extras they were ignored without a word.
  auto extras = j.find("extras");
  if (extras != j.end() && extras->is_object()) {
    for (auto it = extras->begin(); it != extras->end(); ++it) {
      if (it.key().rfind("lightoctree_", 0) != 0) continue;
      fail(path, "invalid glTF: /extras/" + printable(it.key()) +
                     " is read from the scene's extras (/scenes/N/extras/" +
                     printable(it.key()) + "), not the file's: move it there");
    }
  }
}

/// glTF 2.0 alone: a file of another major version, or one whose
/// minVersion asks for a newer 2.x, is not read as its author meant (a
/// version "3.0" or minVersion "9.0" loaded without a word).
static void checkAssetVersion(const std::string& path, const nlohmann::json& j) {
  const auto asset = j.find("asset");
  if (asset == j.end() || !asset->is_object()) return;
  auto majorMinor = [&](const char* key, int& major, int& minor) {
    const auto field = asset->find(key);
    if (field == asset->end()) return false;
    const std::string text = field->get<std::string>();
    const size_t dot = text.find('.');
    auto digits = [](const std::string& part) {
      return !part.empty() && part.size() < 6 &&
             part.find_first_not_of("0123456789") == std::string::npos;
    };
    if (dot == std::string::npos || !digits(text.substr(0, dot)) || !digits(text.substr(dot + 1))) {
      // Cut as the field checks cut a value (a 10 MB version was quoted whole).
      const std::string shown = text.size() > 60 ? text.substr(0, 60) + "..." : text;
      fail(path, std::string("invalid glTF: /asset/") + key + " is \"" + printable(shown) +
                     "\", expected MAJOR.MINOR (\"2.0\")");
    }
    major = std::stoi(text.substr(0, dot));
    minor = std::stoi(text.substr(dot + 1));
    return true;
  };
  int major = 0, minor = 0;
  if (majorMinor("version", major, minor) && major != 2) {
    fail(path, "glTF " + std::to_string(major) + "." + std::to_string(minor) +
                   " (/asset/version): lightoctree reads glTF 2.0");
  }
  if (majorMinor("minVersion", major, minor) && (major != 2 || minor > 0)) {
    fail(path, "needs glTF " + std::to_string(major) + "." + std::to_string(minor) +
                   " (/asset/minVersion): lightoctree reads glTF 2.0");
  }
}

bool readsGltfExtension(const std::string& name) {
  static const char* const kRead[] = {
      "KHR_lights_punctual",          "KHR_materials_emissive_strength", "KHR_materials_ior",
      "KHR_materials_specular",       "KHR_materials_transmission",      "KHR_materials_unlit",
      "KHR_materials_volume",         "KHR_mesh_quantization",           "KHR_texture_transform",
      // Read approximately (gltf_materials.cpp, readSpecularGlossiness), with a warning.
      "KHR_materials_pbrSpecularGlossiness"};
  for (const char* read : kRead) {
    if (name == read) return true;
  }
  return false;
}

/// What a user can do about a required extension the loader does not read.
static std::string unreadExtensionAdvice(const std::string& name) {
  if (name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression") {
    return "its meshes are compressed: write them uncompressed with a glTF tool first";
  }
  if (name == "KHR_texture_basisu" || name == "EXT_texture_webp" || name == "EXT_texture_avif") {
    return "its textures are KTX2, WebP or AVIF images, which the loader does not decode: "
           "convert them to PNG or JPEG with a glTF tool first";
  }
  return "the scene cannot be read as its author meant without it";
}

void prevalidateJson(const std::string& path, const std::string& baseDir, const nlohmann::json& j) {
  if (!j.is_object()) fail(path, "invalid glTF: the top level is not a JSON object");
  auto required = j.find("extensionsRequired");
  if (required != j.end() && required->is_array()) {
    for (const nlohmann::json& e : *required) {
      if (!e.is_string() || readsGltfExtension(e.get<std::string>())) continue;
      // The name as a message may show it: printable ASCII, at most 80.
      std::string name;
      for (char c : e.get<std::string>()) {
        if (name.size() == 80) break;
        name += c >= 0x20 && c < 0x7f ? c : '?';
      }
      fail(path, "requires the glTF extension " + name + ", which lightoctree does not read; " +
                     unreadExtensionAdvice(name));
    }
  }
  checkIntegerRanges(path, j, "", 0);
  checkFieldTypes(path, j);
  checkAssetVersion(path, j);
  std::vector<uint64_t> bufferLengths;
  auto buffers = j.find("buffers");
  if (buffers != j.end() && buffers->is_array()) {
    for (size_t i = 0; i < buffers->size(); ++i) {
      const nlohmann::json& b = (*buffers)[i];
      if (!b.is_object()) fail(path, "buffer " + std::to_string(i) + " is not an object");
      bufferLengths.push_back(jsonUInt(b, "byteLength", 0));
      auto uri = b.find("uri");
      if (uri == b.end() || !uri->is_string()) continue;
      std::string u = uri->get<std::string>();
      std::string what = "buffer " + std::to_string(i);
      if (isDataUri(u)) {
        // Its bytes against byteLength here, named by the buffer: tinygltf's
        // refusal quotes the whole URI (megabytes of base64).
        const int64_t bytes = dataUriBytes(u);
        if (bytes >= 0 && uint64_t(bytes) != bufferLengths.back()) {
          fail(path, what + ": its data URI holds " + std::to_string(bytes) +
                         " bytes where its byteLength says " +
                         std::to_string(bufferLengths.back()) + " (they must be equal)");
        }
        continue;
      }
      std::string file = resolveInsideFolder(path, baseDir, percentDecode(u), what);
      std::error_code ec;
      if (!fs::is_regular_file(file, ec)) {
        fail(path, "missing buffer file '" + u + "' (" + what + ", not found)");
      }
      // Its size against byteLength before anything reads it: the parser
      // reads a buffer file whole and then wants exactly byteLength bytes, so
      // a 16 GiB file behind byteLength 2,496 was read whole to be refused.
      const uintmax_t size = fs::file_size(file, ec);
      if (!ec && size != uintmax_t(bufferLengths.back())) {
        fail(path, what + ": file '" + u + "' holds " + std::to_string(size) +
                       " bytes where its byteLength says " +
                       std::to_string(bufferLengths.back()) + " (they must be equal)");
      }
    }
  }
  std::vector<char> viewOk;
  auto views = j.find("bufferViews");
  if (views != j.end() && views->is_array()) {
    for (size_t i = 0; i < views->size(); ++i) {
      const nlohmann::json& v = (*views)[i];
      if (!v.is_object()) fail(path, "bufferView " + std::to_string(i) + " is not an object");
      uint64_t buffer = jsonUInt(v, "buffer", std::numeric_limits<uint64_t>::max());
      if (buffer >= bufferLengths.size()) {
        fail(path, "bufferView " + std::to_string(i) + " refers to a buffer index out of range");
      }
      uint64_t offset = jsonUInt(v, "byteOffset", 0), length = jsonUInt(v, "byteLength", 0);
      if (offset > bufferLengths[buffer] || length > bufferLengths[buffer] - offset) {
        fail(path, "bufferView " + std::to_string(i) + " (offset " + std::to_string(offset) +
                       ", length " + std::to_string(length) + ") is out of range of buffer " +
                       std::to_string(buffer) + " (" + std::to_string(bufferLengths[buffer]) +
                       " bytes)");
      }
    }
  }
  size_t viewCount = views != j.end() && views->is_array() ? views->size() : 0;
  auto images = j.find("images");
  if (images != j.end() && images->is_array()) {
    for (size_t i = 0; i < images->size(); ++i) {
      const nlohmann::json& im = (*images)[i];
      if (!im.is_object()) fail(path, "image " + std::to_string(i) + " is not an object");
      std::string what = "image " + std::to_string(i);
      auto bv = im.find("bufferView");
      if (bv != im.end() && !(bv->is_number_unsigned() && bv->get<uint64_t>() < viewCount)) {
        fail(path, what + " refers to a bufferView index out of range");
      }
      auto uri = im.find("uri");
      if (uri == im.end() || !uri->is_string()) continue;
      std::string u = uri->get<std::string>();
      if (isDataUri(u)) continue;
      // Inside the folder, or refused; a missing file is the loader's
      // warning (the materials keep their factors), not an error.
      resolveInsideFolder(path, baseDir, percentDecode(u), what);
    }
  }
}

static uint32_t readU32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

/// Checks the GLB container (https://registry.khronos.org/glTF/specs/2.0/
/// glTF-2.0.html#binary-gltf-layout) and returns the JSON chunk.
std::string glbJson(const std::string& path, const std::vector<unsigned char>& bytes) {
  if (bytes.size() < 20) {
    fail(path, "truncated .glb: " + std::to_string(bytes.size()) + " bytes, header needs 20");
  }
  if (std::memcmp(bytes.data(), "glTF", 4) != 0) fail(path, "not a .glb file (bad magic)");
  uint32_t version = readU32(&bytes[4]), length = readU32(&bytes[8]);
  if (version != 2) fail(path, "unsupported .glb version " + std::to_string(version));
  if (length > bytes.size()) {
    fail(path, "truncated .glb: header says " + std::to_string(length) + " bytes, file has " +
                   std::to_string(bytes.size()));
  }
  uint64_t jsonLength = readU32(&bytes[12]);
  if (readU32(&bytes[16]) != 0x4E4F534Au) fail(path, "invalid .glb: first chunk is not JSON");
  if (20 + jsonLength > length) {
    fail(path, "truncated .glb: JSON chunk of " + std::to_string(jsonLength) +
                   " bytes does not fit in the file");
  }
  uint64_t binStart = 20 + jsonLength;
  if (binStart + 8 <= length) {
    uint64_t binLength = readU32(&bytes[binStart]);
    if (binStart + 8 + binLength > length) {
      fail(path, "truncated .glb: BIN chunk of " + std::to_string(binLength) +
                     " bytes does not fit in the file");
    }
  }
  return std::string(reinterpret_cast<const char*>(&bytes[20]), size_t(jsonLength));
}

std::string firstLine(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  size_t nl = s.find('\n');
  if (nl != std::string::npos) s = s.substr(0, nl) + " (...)";
  // tinygltf quotes whole data: URIs: each is cut after its media type.
  for (size_t at = s.find("data:"); at != std::string::npos; at = s.find("data:", at + 5)) {
    size_t end = at;
    while (end < s.size() && s[end] != ' ' && s[end] != '\'' && s[end] != '"') ++end;
    const size_t comma = s.find(',', at);
    const size_t keep = std::min(comma < end ? comma + 1 : end, at + 48);
    if (end - keep > 16) {
      s.replace(keep, end - keep, "... (" + std::to_string(end - at) + " characters)");
    }
  }
  if (s.size() > 240) s = s.substr(0, 240) + "...";
  return s;
}

}  // namespace lo::scene_internal
